// DynamicSurface and StepReport. Settings are read from and written through the core's setters,
// which check them (a setting is a field of a settings struct: get a copy, change the field, set it).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <limits>
#include <optional>

#include "bindings.hpp"
#include "convert.hpp"
#include "solvers/dynamic_surface.hpp"
#include "common/names.hpp"

namespace py = pybind11;

namespace hs {
namespace {

template <class Settings, class Field>
auto getting(const Settings& (DynamicSurface::*get)() const, Field Settings::*field) {
    return [get, field](const DynamicSurface& s) { return (s.*get)().*field; };
}

template <class Settings, class Field>
auto setting(const Settings& (DynamicSurface::*get)() const, void (DynamicSurface::*set)(const Settings&),
             Field Settings::*field) {
    return [get, set, field](DynamicSurface& s, Field value) {
        Settings changed = (s.*get)();
        changed.*field = value;
        (s.*set)(changed);
    };
}

/// A setting given by name (an enumeration): `convert` turns the name into the field's value.
template <class Settings, class Field, class Convert>
auto setting(const Settings& (DynamicSurface::*get)() const, void (DynamicSurface::*set)(const Settings&),
             Field Settings::*field, Convert convert) {
    return [get, set, field, convert](DynamicSurface& s, const std::string& name) {
        Settings changed = (s.*get)();
        changed.*field = convert(name);
        (s.*set)(changed);
    };
}

}  // namespace

void bindSolvers(py::module_& m) {
    m.attr("INTEGRATORS") = namesOf(kIntegratorNames);
    py::class_<StepReport>(m, "StepReport", "What step() did.")
        .def_readonly("substeps", &StepReport::substeps)
        .def_readonly("iterations", &StepReport::iterations)
        .def_readonly("residual", &StepReport::residual)
        .def_readonly("slept", &StepReport::slept)
        .def_readonly("verlet", &StepReport::verlet, "local_global took an explicit velocity Verlet step (stable at this dt)")
        .def_readonly("refused", &StepReport::refused)
        .def_readonly("energy_limited", &StepReport::energyLimited, "the energy guard scaled velocities or refused the step")
        .def_property_readonly("reason", [](const StepReport& r) { return std::string(r.reason); })
        .def_property_readonly("force", [](const StepReport& r) { return Vec3(r.reaction.force); }, "reaction force on the cursor")
        .def_property_readonly("torque", [](const StepReport& r) { return Vec3(r.reaction.torque); }, "reaction torque on the cursor")
        .def("__repr__", [](const StepReport& r) {
            return "StepReport(substeps=" + std::to_string(r.substeps) + ", iterations=" + std::to_string(r.iterations) +
                   ", residual=" + std::to_string(r.residual) + ", slept=" + (r.slept ? "True" : "False") +
                   ", refused=" + (r.refused ? "True" : "False") + ")";
        });

    py::class_<DynamicSurface, std::shared_ptr<DynamicSurface>> ds(m, "DynamicSurface", "A B-spline surface driven by a mass-spring mesh d = A p (paper section 4).");
    ds.def(py::init([](const BSplineSurface& s, std::pair<int, int> mesh) {
               return std::make_shared<DynamicSurface>(s, mesh.first, mesh.second);
           }), py::arg("surface"), py::arg("mesh") = std::make_pair(40, 40),
           "Samples surface on a g x h mesh (at least the control resolution); rest lengths from its shape.")
        .def_property_readonly("controls", [](const DynamicSurface& s) { return std::make_pair(s.surface().nu(), s.surface().nv()); })
        .def_property_readonly("mesh_shape", [](const DynamicSurface& s) { return std::make_pair(s.g(), s.h()); })
        .def_property_readonly("surface", [](const DynamicSurface& s) { return s.surface(); }, "Copy of the current B-spline surface")
        .def_property_readonly("poles", [](py::object self) {
            auto& s = self.cast<DynamicSurface&>();
            return view(s.poles().data(), {s.surface().nu(), s.surface().nv(), 3}, self);
        }, "Read-only (nu, nv, 3) view of the control points")
        .def_property_readonly("velocities", [](py::object self) {
            auto& s = self.cast<DynamicSurface&>();
            return view(s.velocities().data(), {s.surface().nu(), s.surface().nv(), 3}, self);
        }, "Read-only (nu, nv, 3) view of the control-point velocities")
        .def_property_readonly("mesh", [](py::object self) {
            auto& s = self.cast<DynamicSurface&>();
            return view(s.mesh().data(), {s.g(), s.h(), 3}, self);
        }, "Read-only (g, h, 3) view of the mass points d = A p")
        .def("mesh_velocities", [](py::object self) {
            auto& s = self.cast<DynamicSurface&>();
            return view(s.meshVelocities().data(), {s.g(), s.h(), 3}, self);
        }, "(g, h, 3) view of A p' (recomputed by this call)")
        .def_property_readonly("external_forces", [](py::object self) {  // (the point forces and the pull)
            auto& s = self.cast<DynamicSurface&>();
            return view(s.externalForces().data(), {s.g(), s.h(), 3}, self);
        })
        .def_property_readonly("size", &DynamicSurface::size, "Diagonal of the initial mesh's bounding box")
        .def_property("reference", &DynamicSurface::reference, &DynamicSurface::setReference,
                      "(size, spacing_u, spacing_v) of the initial mesh; they scale tolerances and tools")
        .def("set_poles", [](DynamicSurface& s, DoubleArray p) {
            s.setPoles(pointsFrom(p, s.poles().rows(), "poles"));
        }, py::arg("poles"), "Replace the poles (velocities zeroed, rest lengths kept).")
        .def("set_velocities", [](DynamicSurface& s, DoubleArray v) {
            s.setVelocities(pointsFrom(v, s.poles().rows(), "velocities"));
        }, py::arg("velocities"))
        .def("hold_poles", [](DynamicSurface& s, const std::vector<int>& indices, const py::list& links) {
            std::vector<PoleLink> made;
            made.reserve(links.size());
            for (const py::handle item : links) {
                const auto parts = item.cast<py::sequence>();
                if (parts.size() != 2 && parts.size() != 3)
                    throw py::value_error("links: each link is (pole, [(master, weight), ...]) or (pole, masters, offset)");
                PoleLink l{parts[0].cast<int>(), parts[1].cast<std::vector<std::pair<int, double>>>()};
                if (parts.size() == 3) l.offset = vec3(parts[2].cast<std::vector<double>>(), "link offset");
                made.push_back(std::move(l));
            }
            s.holdPoles(indices, made);
        }, py::arg("indices"), py::arg("links") = py::list(),
             "Hard constraints: these poles (index i*nv + j for pole (i, j)) stay exactly where they are, "
             "the others move as if they were walls; each link (pole, [(master, weight), ...][, offset]) keeps a "
             "pole at offset + that combination of its masters (put there at once). Replaces both; [] frees them all.")
        .def_property_readonly("held_poles", &DynamicSurface::heldPoles, "Indices of the held poles, ascending.")
        .def_property_readonly("linked_poles", [](const DynamicSurface& s) {
            py::list out;
            for (const PoleLink& l : s.linkedPoles())
                out.append(py::make_tuple(l.pole, l.masters, py::make_tuple(l.offset.x(), l.offset.y(), l.offset.z())));
            return out;
        }, "The linked poles: [(pole, [(master, weight), ...], (ox, oy, oz)), ...]")
        .def("set_walls", [](DynamicSurface& s, const py::list& walls) {
            std::vector<PoleWall> made;
            made.reserve(walls.size());
            for (const py::handle item : walls) {
                const auto parts = item.cast<py::sequence>();
                if (parts.size() != 3) throw py::value_error("walls: each wall is (point, normal, [pole, ...])");
                made.push_back({vec3(parts[0].cast<std::vector<double>>(), "wall point"),
                                vec3(parts[1].cast<std::vector<double>>(), "wall normal"), parts[2].cast<std::vector<int>>()});
            }
            s.setWalls(made);
        }, py::arg("walls"),
             "Walls: each (point, normal, [pole, ...]) is a plane the listed poles (index i*nv + j) stay behind "
             "(on the side the normal faces away from); a step that carries a free pole out puts it back onto "
             "the plane. A face sculpted in place stays behind the planes of the faces it meets at creases. "
             "Replaces them all; [] removes them.")
        .def_property_readonly("walls", [](const DynamicSurface& s) {
            py::list out;
            for (const PoleWall& w : s.walls())
                out.append(py::make_tuple(py::make_tuple(w.point.x(), w.point.y(), w.point.z()),
                                          py::make_tuple(w.normal.x(), w.normal.y(), w.normal.z()), w.poles));
            return out;
        }, "The walls: [((px, py, pz), (nx, ny, nz), [pole, ...]), ...], normals unit.")
        .def("set_symmetry", [](DynamicSurface& s, int direction, const std::vector<double>& point, const std::vector<double>& normal) {
            s.setSymmetry(direction, vec3(point, "symmetry point"), vec3(normal, "symmetry normal"));
        }, py::arg("direction"), py::arg("point"), py::arg("normal"),
             "Mirror symmetry: the surface is its own mirror image in the plane (point, normal) with parameter "
             "direction 0 (u) or 1 (v) reversed, and stays exactly so (strokes act mirrored too). Validated: "
             "ValueError naming symmetry when the net is not symmetric. Direction -1 removes it.")
        .def_property_readonly("symmetry", [](const DynamicSurface& s) -> py::object {
            const MirrorSymmetry& sym = s.symmetry();
            if (sym.empty()) return py::none();
            return py::make_tuple(sym.direction(), std::vector<double>(sym.point().data(), sym.point().data() + 3),
                                  std::vector<double>(sym.normal().data(), sym.normal().data() + 3));
        }, "None, or (direction, point, normal) of the mirror symmetry")
        .def("sampling_matrix", [](const DynamicSurface& s) {
            const CsrMatrix& a = s.sampling().matrix();
            return py::make_tuple(a.rowStart, a.col, a.value, std::make_pair(a.rows, a.cols));
        }, "A as CSR (indptr, indices, data, shape); row a*h + b is mesh point (a, b), column i*nv + j pole (i, j)")
        .def_property_readonly("mesh_parameters_u", [](const DynamicSurface& s) { return s.sampling().us(); })
        .def_property_readonly("mesh_parameters_v", [](const DynamicSurface& s) { return s.sampling().vs(); })
        .def("mesh_index_at", &DynamicSurface::meshIndexAt, py::arg("u"), py::arg("v"))
        .def("mesh_parameters", &DynamicSurface::meshParameters, py::arg("index"))
        .def("nearest_mesh_index", [](const DynamicSurface& s, const std::vector<double>& x) {
            return s.nearestMeshIndex(vec3(x, "point"));
        }, py::arg("point"))
        // material
        .def_property_readonly("mass_map", py::overload_cast<>(&DynamicSurface::massMap), py::return_value_policy::reference_internal)
        .def_property_readonly("damping_map", py::overload_cast<>(&DynamicSurface::dampingMap), py::return_value_policy::reference_internal)
        .def_property_readonly("stiffness_map", py::overload_cast<>(&DynamicSurface::stiffnessMap), py::return_value_policy::reference_internal)
        .def_property_readonly("bending_map", py::overload_cast<>(&DynamicSurface::bendingMap), py::return_value_policy::reference_internal,
                               "Bending (thin-plate) weight beta per mesh cell, in the springs' units; 0 switches it off")
        .def_property_readonly("pull_map", py::overload_cast<>(&DynamicSurface::pullMap), py::return_value_policy::reference_internal,
                               "Where the pull toward the target acts, as a factor of its strength (0: not there)")
        .def("set_pull_target", [](DynamicSurface& s, std::shared_ptr<PointTree> tree, double reach) {
            s.setPullTarget(std::move(tree), reach);
        }, py::arg("tree"), py::arg("reach") = 1.0,
           "The scan the data springs pull toward (a PointTree, shared; None: none) and the reach (mm) beyond which "
           "a scan point does not pull; every anchor is sought afresh.")
        .def("set_pull", &DynamicSurface::setPull, py::arg("enabled"), py::arg("strength") = 1.0,
             "Switch the pull toward the target on or off, at strength (0..1e6; 1: a mesh point alone would reach "
             "the scan in about 1/8 s).")
        .def_property_readonly("pull", [](const DynamicSurface& s) {
            const DataSprings& p = s.pull();
            py::dict d;
            d["enabled"] = p.enabled();
            d["strength"] = p.strength();
            d["target"] = static_cast<bool>(p.target());
            d["reach"] = p.reach();
            d["active"] = p.active();
            d["anchored"] = p.anchored();
            return d;
        }, "The pull toward the target: enabled, strength, target (whether one is set), reach, active, anchored "
           "(mesh points that have a scan point to pull toward)")
        .def_property_readonly("bending_reference", [](py::object self) {
            auto& s = self.cast<DynamicSurface&>();
            return view(s.bending().reference().data(), {s.g(), s.h(), 3}, self).attr("copy")();
        }, "(g, h, 3) copy of the shape the bending energy measures from")
        .def("set_bending_reference", [](DynamicSurface& s, DoubleArray r) {
            s.setBendingReference(pointsFrom(r, static_cast<Eigen::Index>(s.g()) * s.h(), "reference"));
        }, py::arg("reference"), "Replace the bending energy's reference shape ((g, h, 3) or (g*h, 3)).")
        .def("fit_poles", [](DynamicSurface& s, DoubleArray targets, const Eigen::MatrixX2d& uv, DoubleArray normals,
                             const Eigen::VectorXd& weights, double tangential, double smoothing, double inPlane,
                             double beyond) {
            if (targets.ndim() != 2 || targets.shape(1) != 3) throw std::invalid_argument("targets: expected an (n, 3) array");
            const auto n = static_cast<Eigen::Index>(targets.shape(0));
            const Points t = pointsFrom(targets, n, "targets");
            if (normals.ndim() != 2 || normals.shape(0) != n || normals.shape(1) != 3)
                throw std::invalid_argument("normals: expected an (n, 3) array, one per target point");
            Points nn(n, 3);
            std::copy(normals.data(), normals.data() + 3 * n, nn.data());
            Points fitted;
            {
                py::gil_scoped_release release;
                fitted = s.fitPoles(t, uv, nn, weights, tangential, smoothing, inPlane, beyond);
            }
            Eigen::MatrixXd out = fitted;
            return out;
        }, py::arg("targets"), py::arg("uv"), py::arg("normals"), py::arg("weights"), py::arg("tangential") = 0.1,
           py::arg("smoothing") = 1e-5, py::arg("in_plane") = 0.0, py::arg("beyond") = 0.0,
           "The poles ((nu * nv, 3)) that bring the surface nearest targets ((n, 3)) at parameters uv ((n, 2)) with "
           "the surface's normals there ((n, 3)), weighted (n,), the slide along the surface weighed by tangential "
           "(1 = plain least squares), with the mesh's curvature variation at smoothing (relative) bridging where "
           "there are no points, each pole's move in the surface's own plane weighed by in_plane (relative) and the "
           "change's slope by beyond (relative) past the points' reach; held and linked poles and the symmetry hold. "
           "The surface is not changed.")
        .def("fair", [](DynamicSurface& s, const Eigen::VectorXd& weights, double strength) { s.fair(weights, strength); },
             py::arg("weights"), py::arg("strength") = 10.0,
             "Relax the curvature variation where weights (one per mesh point, row a*h + b, in [0, 1]) ask, "
             "by strength against staying put; held and linked poles and symmetry hold.")
        .def_property_readonly("bending_energy", &DynamicSurface::bendingEnergy,
                               "The bending energy at the current mesh")
        .def_property_readonly("spring_count", [](const DynamicSurface& s) { return s.springs().size(); })
        .def_property_readonly("rest_lengths", [](py::object self) {
            const auto& s = self.cast<const DynamicSurface&>();  // a read-only view (no copy)
            return view(s.springs().rest().data(), {static_cast<py::ssize_t>(s.springs().rest().size())}, self);
        })
        .def("set_rest_lengths", [](DynamicSurface& s, const std::vector<double>& r) { s.springs().setRest(r); }, py::arg("rest"))
        .def("relax", &DynamicSurface::relax,
             "Make the current shape the rest shape (rest lengths and bending reference from the current mesh).")
        .def("set_stiffness_law", [](DynamicSurface& s, const std::string& kind, double scale) {
            s.setStiffnessLaw({fromName(kLawNames, kind, "law"), scale});
        },
             py::arg("kind"), py::arg("scale") = 1.0, "linear, cubic (g = x + x^3/s^2) or saturating (g = s tanh(x/s)) spring force")
        .def_property_readonly("stiffness_law", [](const DynamicSurface& s) { return std::make_pair(std::string(nameOf(kLawNames, s.springs().law.kind)), s.springs().law.scale); })
        .def("set_damping_law", [](DynamicSurface& s, const std::string& kind, double scale) {
            s.setDampingLaw({fromName(kLawNames, kind, "law"), scale});
        },
             py::arg("kind"), py::arg("scale") = 1.0, "damping multiplied by g(F)/F of each point's spring-force magnitude F")
        .def_property_readonly("damping_law", [](const DynamicSurface& s) { return std::make_pair(std::string(nameOf(kLawNames, s.dampingLaw().kind)), s.dampingLaw().scale); })
        .def("set_plasticity", [](DynamicSurface& s, bool enabled, double yieldStrain, double rate) {
            s.setPlasticity({enabled, yieldStrain, rate});
        }, py::arg("enabled"), py::arg("yield_strain") = 0.05, py::arg("rate") = 1.0,
           "Past yield_strain the rest length creeps toward the current length at rate (1/s).")
        .def_property_readonly("plasticity", [](const DynamicSurface& s) {
            const auto& p = s.springs().plasticity;
            return py::make_tuple(p.enabled, p.yieldStrain, p.rate);
        })
        // forces and tools
        .def("set_point_force", [](DynamicSurface& s, int index, const std::vector<double>& f) { s.setPointForce(index, vec3(f, "force")); },
             py::arg("index"), py::arg("force"), "Persistent external force on a mesh point (clamped to max_point_force).")
        .def("clear_forces", &DynamicSurface::clearForces)
        .def_property("max_point_force", &DynamicSurface::maxPointForce, &DynamicSurface::setMaxPointForce,
                      "largest external force on one mesh point (> 0)")
        .def("set_tool", &DynamicSurface::setTool, py::arg("name"), "rope, magnet, orientation or smooth")
        .def_property_readonly("tool", py::overload_cast<>(&DynamicSurface::tool), py::return_value_policy::reference_internal)
        .def("set_cursor", [](DynamicSurface& s, const std::vector<double>& position, const std::vector<double>& orientation, bool grab) {
            if (orientation.size() != 4) throw std::invalid_argument("orientation: expected a quaternion (w, x, y, z)");
            Cursor c;
            c.position = vec3(position, "position");
            c.orientation = Eigen::Quaterniond(orientation[0], orientation[1], orientation[2], orientation[3]);
            c.grab = grab;
            s.setCursor(c);
        }, py::arg("position"), py::arg("orientation") = std::vector<double>{1, 0, 0, 0}, py::arg("grab") = false,
           "Latest cursor; grab going True grabs with the current tool, False releases.")
        // constraints
        .def("add_constraint", [](DynamicSurface& s, const std::string& kind, std::optional<int> index,
                                  std::optional<std::pair<double, double>> uv, std::optional<std::vector<double>> near,
                                  std::optional<double> stiffness, std::optional<std::vector<double>> target,
                                  std::optional<std::pair<double, double>> curvature) {
            const ConstraintKind k = fromName(kConstraintNames, kind, "kind");
            const int given = (index ? 1 : 0) + (uv ? 1 : 0) + (near ? 1 : 0);
            if (given != 1) throw std::invalid_argument("index/uv/near: give exactly one location");
            int point = index ? *index : uv ? s.meshIndexAt(uv->first, uv->second) : s.nearestMeshIndex(vec3(*near, "near"));
            if (target && k == ConstraintKind::Curvature) throw std::invalid_argument("target: use curvature=(ku, kv) for curvature");
            if (curvature && k != ConstraintKind::Curvature) throw std::invalid_argument("curvature: only for kind='curvature'");
            Vec3 t;
            if (target) t = vec3(*target, "target");
            double ku = 0, kv = 0;
            if (curvature) { ku = curvature->first; kv = curvature->second; }
            const double k0 = stiffness ? *stiffness : s.defaultConstraintStiffness();
            int id = s.constraints().add(k, point, k0, s.mesh(), target ? &t : nullptr, curvature ? &ku : nullptr, curvature ? &kv : nullptr);
            return id;
        }, py::arg("kind"), py::arg("index") = py::none(), py::arg("uv") = py::none(), py::arg("near") = py::none(),
           py::arg("stiffness") = py::none(), py::arg("target") = py::none(), py::arg("curvature") = py::none(),
           "Penalty constraint at a mesh index, at (u, v), or at the mass point nearest `near`. kind: point (target: "
           "position), tangent (target: plane normal; fixes rotation), normal (target: normal; rotation free), "
           "curvature (curvature=(ku, kv), magnitudes). Targets default to the current values. Returns an id.")
        .def("remove_constraint", [](DynamicSurface& s, int id) { s.constraints().remove(id); }, py::arg("id"))
        .def("clear_constraints", [](DynamicSurface& s) { s.constraints().clear(); })
        .def("set_constraint_stiffness", [](DynamicSurface& s, int id, double k) { s.constraints().setStiffness(id, k); }, py::arg("id"), py::arg("stiffness"))
        .def("set_constraint_target", [](DynamicSurface& s, int id, const std::vector<double>& t) { s.constraints().setTarget(id, vec3(t, "target")); },
             py::arg("id"), py::arg("target"))
        .def("set_constraint_curvature", [](DynamicSurface& s, int id, double ku, double kv) { s.constraints().setCurvature(id, ku, kv); },
             py::arg("id"), py::arg("ku"), py::arg("kv"))
        .def("constraint_error", [](DynamicSurface& s, int id) { return s.constraints().error(s.constraints().get(id), s.mesh()); },
             py::arg("id"), "point: distance; tangent/normal: angle (rad); curvature: relative error (larger of u, v)")
        .def_property_readonly("constraints", [](const DynamicSurface& s) {
            py::list out;
            for (const Constraint& c : s.constraints().items()) {
                py::dict d;
                d["id"] = c.id; d["kind"] = nameOf(kConstraintNames, c.kind); d["index"] = c.point; d["stiffness"] = c.stiffness;
                d["uv"] = s.meshParameters(c.point);
                if (c.kind == ConstraintKind::Curvature) d["curvature"] = std::make_pair(c.curvatureU, c.curvatureV);
                else d["target"] = std::vector<double>{c.target.x(), c.target.y(), c.target.z()};
                if (c.kind == ConstraintKind::Tangent || c.kind == ConstraintKind::Normal) {
                    std::vector<double> o;
                    for (const Vec3& x : c.offsets) o.insert(o.end(), {x.x(), x.y(), x.z()});
                    d["offsets"] = o;
                }
                out.append(d);
            }
            return out;
        }, "List of constraints as dicts (id, kind, index, uv, stiffness, target or curvature)")
        .def("restore_constraint", [](DynamicSurface& s, int id, const std::string& kind, int index, double stiffness,
                                      std::optional<std::vector<double>> target, std::optional<std::pair<double, double>> curvature,
                                      std::optional<std::vector<double>> offsets) {
            Constraint c;
            c.id = id;
            c.kind = fromName(kConstraintNames, kind, "kind");
            c.point = index;
            c.stiffness = stiffness;
            const bool needsTarget = c.kind != ConstraintKind::Curvature;
            if (needsTarget != bool(target)) throw std::invalid_argument(needsTarget ? "target: required" : "target: not for curvature");
            if (!needsTarget && !curvature) throw std::invalid_argument("curvature: required");
            if (target) c.target = vec3(*target, "target");
            if (curvature) { c.curvatureU = std::abs(curvature->first); c.curvatureV = std::abs(curvature->second); }
            const bool framed = c.kind == ConstraintKind::Tangent || c.kind == ConstraintKind::Normal;
            if (framed != bool(offsets)) throw std::invalid_argument(framed ? "offsets: required" : "offsets: only for tangent and normal");
            if (offsets) {
                if (offsets->size() != 12) throw std::invalid_argument("offsets: expected 12 numbers");
                for (int k = 0; k < 4; ++k) c.offsets[k] = Vec3((*offsets)[3 * k], (*offsets)[3 * k + 1], (*offsets)[3 * k + 2]);
            }
            s.constraints().restore(c);
        }, py::arg("id"), py::arg("kind"), py::arg("index"), py::arg("stiffness"), py::arg("target") = py::none(),
           py::arg("curvature") = py::none(), py::arg("offsets") = py::none(),
           "Re-insert a constraint exactly as listed by `constraints` (id, offsets and targets kept).")
        .def_property("constraint_stiffness_factor", &DynamicSurface::constraintStiffnessFactor,
                      &DynamicSurface::setConstraintStiffnessFactor, "default penalty stiffness = factor * mean material stiffness (> 0)")
        .def("mesh_curvature", &DynamicSurface::meshCurvature, py::arg("index"), py::arg("direction"), "Curvature of the circle through a point and its two neighbours along u (0) or v (1)")
        // stepping
        .def_property("integrator", [](const DynamicSurface& s) { return std::string(nameOf(kIntegratorNames, s.solver().kind)); },
                      setting(&DynamicSurface::solver, &DynamicSurface::setSolver, &SolverSettings::kind,
                              [](const std::string& k) { return fromName(kIntegratorNames, k, "integrator"); }),
                      "explicit (paper eq. 8-9, adaptive halving), implicit (backward Euler, CG) or local_global (default: "
                      "BDF2 by local/global iterations, velocity Verlet where that is provably stable)")
        .def_property("iterations", getting(&DynamicSurface::solver, &SolverSettings::iterations),
                      setting(&DynamicSurface::solver, &DynamicSurface::setSolver, &SolverSettings::iterations))
        .def_property("time_order", getting(&DynamicSurface::solver, &SolverSettings::timeOrder),
                      setting(&DynamicSurface::solver, &DynamicSurface::setSolver, &SolverSettings::timeOrder),
                      "local_global's time discretisation: 2 = BDF2 (default, second order), 1 = backward Euler")
        .def_property("explicit_when_stable", getting(&DynamicSurface::solver, &SolverSettings::explicitWhenStable),
                      setting(&DynamicSurface::solver, &DynamicSurface::setSolver, &SolverSettings::explicitWhenStable),
                      "local_global: take an explicit velocity Verlet step wherever it is provably stable for the "
                      "step (cheaper and more accurate there), the implicit step elsewhere (default on)")
        .def_property("regional", [](const DynamicSurface& s) { return s.solver().region.enabled; },
                      [](DynamicSurface& s, bool on) { SolverSettings v = s.solver(); v.region.enabled = on; s.setSolver(v); },
                      "local_global: step only the region of poles a stroke moves (plus a margin), the rest held "
                      "at rest until the motion reaches it; where the scene allows it (no symmetry, linked poles, "
                      "penalty constraints or point forces; linear laws; a tool that says where it pushes)")
        .def_property("region_margin", [](const DynamicSurface& s) { return s.solver().region.margin; },
                      [](DynamicSurface& s, int n) { SolverSettings v = s.solver(); v.region.margin = n; s.setSolver(v); },
                      "quiet poles kept free around the moving ones (1..1000)")
        .def_property("region_wake", [](const DynamicSurface& s) { return s.solver().region.wake; },
                      [](DynamicSurface& s, double f) { SolverSettings v = s.solver(); v.region.wake = f; s.setSolver(v); },
                      "a pole counts as moving above this fraction of the fastest pole's speed (0..1)")
        .def_property_readonly("active_region", [](const DynamicSurface& s) {
            const ActiveRegion& r = s.activeRegion();
            py::dict d;
            d["whole"] = r.whole;
            d["poles"] = py::make_tuple(r.poles.r0, r.poles.r1, r.poles.c0, r.poles.c1);
            d["mesh"] = py::make_tuple(r.mesh.r0, r.mesh.r1, r.mesh.c0, r.mesh.c1);
            d["changes"] = r.serial;
            return d;
        }, "what the last step moved: whole (bool), poles and mesh as (row0, row1, col0, col1) half-open "
           "index ranges along u and v, and how many times the region changed")
        .def_property("cg_iterations", getting(&DynamicSurface::solver, &SolverSettings::cgIterations),
                      setting(&DynamicSurface::solver, &DynamicSurface::setSolver, &SolverSettings::cgIterations))
        .def_property("acceleration_limit", getting(&DynamicSurface::solver, &SolverSettings::accelerationLimit),
                      setting(&DynamicSurface::solver, &DynamicSurface::setSolver, &SolverSettings::accelerationLimit))
        .def_property("max_halvings", getting(&DynamicSurface::solver, &SolverSettings::maxHalvings),
                      setting(&DynamicSurface::solver, &DynamicSurface::setSolver, &SolverSettings::maxHalvings))
        .def_property("sleep_enabled", getting(&DynamicSurface::sleep, &SleepSettings::enabled),
                      setting(&DynamicSurface::sleep, &DynamicSurface::setSleep, &SleepSettings::enabled))
        .def_property("sleep_tolerance", getting(&DynamicSurface::sleep, &SleepSettings::tolerance),
                      setting(&DynamicSurface::sleep, &DynamicSurface::setSleep, &SleepSettings::tolerance))
        .def_property("energy_guard", getting(&DynamicSurface::energyGuard, &EnergyGuardSettings::enabled),
                      setting(&DynamicSurface::energyGuard, &DynamicSurface::setEnergyGuard, &EnergyGuardSettings::enabled),
                      "keep kinetic + potential energy within (1 + energy_slack) x (energy at the last change + work "
                      "put in); runs for explicit, implicit, non-linear laws, curvature constraints and very long steps")
        .def_property("energy_slack", getting(&DynamicSurface::energyGuard, &EnergyGuardSettings::slack),
                      setting(&DynamicSurface::energyGuard, &DynamicSurface::setEnergyGuard, &EnergyGuardSettings::slack))
        .def_property_readonly("verlet_step_limit", &DynamicSurface::verletStepLimit,
                               "longest step local_global takes by its explicit Verlet branch now (0: never)")
        .def_property_readonly("energy_ceiling", &DynamicSurface::energyCeiling,
                               "the energy guard's ceiling (0 when the guard is not running for this scene)")
        .def_property_readonly("asleep", &DynamicSurface::asleep)
        .def("wake", &DynamicSurface::wake)
        .def("step", [](DynamicSurface& s, double dt, int steps) {
            requireInRange(steps, "steps", 1, std::numeric_limits<int>::max());
            StepReport total;
            {
                py::gil_scoped_release release;
                for (int i = 0; i < steps; ++i) {
                    const StepReport r = s.step(dt);
                    total.substeps += r.substeps;
                    total.iterations += r.iterations;
                    total.residual = r.residual;
                    total.slept = r.slept;
                    total.verlet = r.verlet;
                    total.reaction = r.reaction;
                    if (r.energyLimited) { total.energyLimited = true; total.reason = r.reason; }
                    if (r.refused) { total.refused = true; total.reason = r.reason; break; }
                }
            }
            return total;
        }, py::arg("dt"), py::arg("steps") = 1,
           "Advance `steps` steps of dt seconds (GIL released). Returns totals of substeps and iterations and the "
           "last residual and reaction; stops at a refused step (state kept).")
        .def_property_readonly("time", &DynamicSurface::time)
        .def_property_readonly("step_count", &DynamicSurface::stepCount)
        .def_property_readonly("system_solve_size", &DynamicSurface::systemSolveSize,
                               "(unknowns, matrix entries one solve reads, how: 'dense' inverse, 'band' or 'sparse' "
                               "factor) of the system the last implicit step solved by; (0, 0, '') before one")
        .def_property_readonly("work_done", &DynamicSurface::workDone, "work of external and tool forces so far")
        .def("kinetic_energy", &DynamicSurface::kineticEnergy)
        .def("potential_energy", &DynamicSurface::potentialEnergy, "springs, bending and penalty terms")
        .def("potential_gradient", [](DynamicSurface& s) {
            const Points& g = s.potentialGradient();
            const auto [nu, nv] = std::make_pair(s.surface().nu(), s.surface().nv());
            py::array_t<double> out({nu, nv, 3});
            std::copy(g.data(), g.data() + g.size(), out.mutable_data());
            return out;
        }, "Gradient of potential_energy() with respect to the poles (nu, nv, 3): -A^T f(d), springs, bending and constraints")
        .def("point_masses", [](DynamicSurface& s) { return Eigen::VectorXd(s.pointMasses()); })
        .def("curvature_grid", [](const DynamicSurface& s) {
            Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> c;
            {
                py::gil_scoped_release release;
                c = s.curvatureGrid();
            }
            py::array_t<double> a({s.g(), s.h(), 6});
            std::copy(c.data(), c.data() + c.size(), a.mutable_data());
            return a;
        }, "(g, h, 6): u and v normal curvature, min and max principal, mean, Gaussian at the mesh parameters");
}

}  // namespace hs
