// Python binding of the dynamics core. Buffers are numpy views (no copies) whose base keeps the
// owner alive; views of the state are read-only so nothing unchecked enters it.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <optional>
#include <stdexcept>

#include "dynamic_surface.hpp"
#include "runtime_bindings.hpp"

namespace py = pybind11;
using namespace hs;

namespace {

py::array view(const double* data, std::vector<py::ssize_t> shape, py::handle owner) {
    std::vector<py::ssize_t> strides(shape.size());
    py::ssize_t s = sizeof(double);
    for (size_t i = shape.size(); i-- > 0;) { strides[i] = s; s *= shape[i]; }
    py::array a(py::dtype::of<double>(), shape, strides, data, owner);
    a.attr("setflags")(py::arg("write") = false);
    return a;
}

Points pointsFrom(const py::array_t<double, py::array::c_style | py::array::forcecast>& a, Eigen::Index rows,
                  const char* name) {
    if (a.ndim() < 2 || a.shape(a.ndim() - 1) != 3 || a.size() != rows * 3)
        throw std::invalid_argument(std::string(name) + ": expected " + std::to_string(rows) + " points of 3 coordinates");
    Points p(rows, 3);
    std::copy(a.data(), a.data() + rows * 3, p.data());
    if (!withinRange(p)) throw std::invalid_argument(std::string(name) + ": must be finite and within +-1e9");
    return p;
}

Vec3 vec3(const std::vector<double>& v, const char* name) {
    if (v.size() != 3) throw std::invalid_argument(std::string(name) + ": expected 3 numbers");
    Vec3 r(v[0], v[1], v[2]);
    if (!withinRange(r)) throw std::invalid_argument(std::string(name) + ": must be finite and within +-1e9");
    return r;
}

Falloff falloffFrom(const std::string& s) {
    if (s == "constant") return Falloff::Constant;
    if (s == "spherical") return Falloff::Spherical;
    if (s == "cylindrical") return Falloff::Cylindrical;
    if (s == "conical") return Falloff::Conical;
    throw std::invalid_argument("falloff: unknown '" + s + "' (constant, spherical, cylindrical, conical)");
}
std::string falloffName(Falloff f) {
    switch (f) {
        case Falloff::Constant: return "constant";
        case Falloff::Spherical: return "spherical";
        case Falloff::Cylindrical: return "cylindrical";
        case Falloff::Conical: return "conical";
    }
    return "";
}

LawKind lawFrom(const std::string& s) {
    if (s == "linear") return LawKind::Linear;
    if (s == "cubic") return LawKind::CubicHardening;
    if (s == "saturating") return LawKind::Saturating;
    throw std::invalid_argument("law: unknown '" + s + "' (linear, cubic, saturating)");
}
std::string lawName(LawKind k) {
    return k == LawKind::Linear ? "linear" : k == LawKind::CubicHardening ? "cubic" : "saturating";
}
ResponseLaw makeLaw(const std::string& kind, double scale) {
    if (!(scale >= 1e-12 && scale <= 1e12)) throw std::invalid_argument("scale: must be in [1e-12, 1e12]");
    return {lawFrom(kind), scale};
}

IntegratorKind integratorFrom(const std::string& s) {
    if (s == "explicit") return IntegratorKind::Explicit;
    if (s == "implicit") return IntegratorKind::ImplicitCG;
    if (s == "local_global") return IntegratorKind::LocalGlobal;
    throw std::invalid_argument("integrator: unknown '" + s + "' (explicit, implicit, local_global)");
}
std::string integratorName(IntegratorKind k) {
    return k == IntegratorKind::Explicit ? "explicit" : k == IntegratorKind::ImplicitCG ? "implicit" : "local_global";
}

ConstraintKind constraintFrom(const std::string& s) {
    if (s == "point") return ConstraintKind::Point;
    if (s == "tangent") return ConstraintKind::Tangent;
    if (s == "normal") return ConstraintKind::Normal;
    if (s == "curvature") return ConstraintKind::Curvature;
    throw std::invalid_argument("kind: unknown constraint '" + s + "' (point, tangent, normal, curvature)");
}
std::string constraintName(ConstraintKind k) {
    switch (k) {
        case ConstraintKind::Point: return "point";
        case ConstraintKind::Tangent: return "tangent";
        case ConstraintKind::Normal: return "normal";
        case ConstraintKind::Curvature: return "curvature";
    }
    return "";
}

py::dict derivativesDict(const SurfaceDerivatives& d) {
    py::dict r;
    r["point"] = d.s; r["du"] = d.su; r["dv"] = d.sv; r["duu"] = d.suu; r["duv"] = d.suv; r["dvv"] = d.svv;
    return r;
}
py::dict curvatureDict(const Curvature& c) {
    py::dict r;
    r["u"] = c.ku; r["v"] = c.kv; r["min"] = c.kmin; r["max"] = c.kmax; r["mean"] = c.mean; r["gauss"] = c.gauss;
    return r;
}

void checkParam(double v, const char* name, bool allowZero = false) {
    if (!std::isfinite(v) || v < 0 || (!allowZero && v == 0))
        throw std::invalid_argument(std::string(name) + ": must be finite and " + (allowZero ? ">= 0" : "> 0"));
}

// Defines a validated positive double property.
template <class C, class T>
void positive(py::class_<C, T>& cls, const char* name, double C::*member, const char* doc, bool allowZero = false) {
    cls.def_property(
        name, [member](const C& c) { return c.*member; },
        [member, name, allowZero](C& c, double v) { checkParam(v, name, allowZero); c.*member = v; }, doc);
}

}  // namespace

PYBIND11_MODULE(_core, m) {
    m.doc() = "HapticSculpt dynamics core: dynamic B-spline surfaces (Dachille et al.), tools, constraints, integrators.";
    m.attr("MAX_DEGREE") = kMaxDegree;

    py::class_<BSplineSurface>(m, "BSplineSurface", "Tensor-product B-spline surface, rational with fixed weights if weights are given.")
        .def(py::init([](py::array_t<double, py::array::c_style | py::array::forcecast> poles, std::pair<int, int> degree,
                         std::optional<std::vector<double>> knotsU, std::optional<std::vector<double>> knotsV,
                         std::optional<py::array_t<double, py::array::c_style | py::array::forcecast>> weights) {
                 if (poles.ndim() != 3 || poles.shape(2) != 3)
                     throw std::invalid_argument("poles: expected an array of shape (nu, nv, 3)");
                 const int nu = static_cast<int>(poles.shape(0)), nv = static_cast<int>(poles.shape(1));
                 if (degree.first < 1 || degree.first > kMaxDegree || degree.second < 1 || degree.second > kMaxDegree)
                     throw std::invalid_argument("degree: each must be in 1.." + std::to_string(kMaxDegree));
                 if (nu < degree.first + 1 || nv < degree.second + 1)
                     throw std::invalid_argument("poles: need at least degree+1 control points in each direction");
                 Points P = pointsFrom(poles, static_cast<Eigen::Index>(nu) * nv, "poles");
                 Eigen::VectorXd w;
                 if (weights) {
                     if (weights->size() != static_cast<py::ssize_t>(nu) * nv)
                         throw std::invalid_argument("weights: expected shape (nu, nv)");
                     w = Eigen::Map<const Eigen::VectorXd>(weights->data(), weights->size());
                 }
                 return BSplineSurface(nu, nv, degree.first, degree.second,
                                       knotsU ? *knotsU : clampedUniformKnots(nu, degree.first),
                                       knotsV ? *knotsV : clampedUniformKnots(nv, degree.second), std::move(P), std::move(w));
             }),
             py::arg("poles"), py::arg("degree") = std::make_pair(3, 3), py::arg("knots_u") = py::none(),
             py::arg("knots_v") = py::none(), py::arg("weights") = py::none(),
             "poles: (nu, nv, 3); degree: (p, q) in 1..5; knots: full non-decreasing vectors (clamped uniform by default); "
             "weights: (nu, nv) > 0 or None.")
        .def_static("plane", [](std::pair<int, int> controls, std::pair<int, int> degree, std::pair<double, double> size) {
                if (degree.first < 1 || degree.first > kMaxDegree || degree.second < 1 || degree.second > kMaxDegree)
                    throw std::invalid_argument("degree: each must be in 1.." + std::to_string(kMaxDegree));
                if (controls.first < degree.first + 1 || controls.second < degree.second + 1)
                    throw std::invalid_argument("controls: need at least degree+1 control points in each direction");
                return BSplineSurface::plane(controls.first, controls.second, degree.first, degree.second, size.first, size.second);
            }, py::arg("controls") = std::make_pair(8, 8), py::arg("degree") = std::make_pair(3, 3),
            py::arg("size") = std::make_pair(100.0, 100.0), "Flat clamped-uniform patch in the XY plane centred at the origin.")
        .def_property_readonly("controls", [](const BSplineSurface& s) { return std::make_pair(s.nu(), s.nv()); })
        .def_property_readonly("degree", [](const BSplineSurface& s) { return std::make_pair(s.knotsU().degree(), s.knotsV().degree()); })
        .def_property_readonly("knots_u", [](const BSplineSurface& s) { return s.knotsU().knots(); })
        .def_property_readonly("knots_v", [](const BSplineSurface& s) { return s.knotsV().knots(); })
        .def_property_readonly("rational", &BSplineSurface::rational)
        .def_property_readonly("weights", [](const BSplineSurface& s) -> py::object {
            if (!s.rational()) return py::none();
            Eigen::MatrixXd w = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(s.weights().data(), s.nu(), s.nv());
            return py::cast(w);
        }, "(nu, nv) weights, or None when non-rational")
        .def_property_readonly("poles", [](const BSplineSurface& s) {
            py::array_t<double> a({s.nu(), s.nv(), 3});
            std::copy(s.poles().data(), s.poles().data() + s.poles().size(), a.mutable_data());
            return a;
        }, "(nu, nv, 3) copy of the poles")
        .def_property_readonly("domain", [](const BSplineSurface& s) {
            return std::make_pair(std::make_pair(s.knotsU().domainStart(), s.knotsU().domainEnd()),
                                  std::make_pair(s.knotsV().domainStart(), s.knotsV().domainEnd()));
        })
        .def("evaluate", [](const BSplineSurface& s, double u, double v) { return derivativesDict(s.evaluate(u, v, 2)); },
             py::arg("u"), py::arg("v"), "Point and first and second partial derivatives at (u, v).")
        .def("normal", &BSplineSurface::normal, py::arg("u"), py::arg("v"), "Unit normal du x dv / |du x dv|.")
        .def("grid", [](const BSplineSurface& s, int nu, int nv) {
            if (nu < 2 || nv < 2 || nu > 4096 || nv > 4096) throw std::invalid_argument("nu, nv: each must be in [2, 4096]");
            const double u0 = s.knotsU().domainStart(), u1 = s.knotsU().domainEnd();
            const double v0 = s.knotsV().domainStart(), v1 = s.knotsV().domainEnd();
            py::array_t<double> points({nu, nv, 3}), normals({nu, nv, 3});
            auto p = points.mutable_unchecked<3>();
            auto n = normals.mutable_unchecked<3>();
            {
                py::gil_scoped_release release;
                for (int i = 0; i < nu; ++i)
                    for (int j = 0; j < nv; ++j) {
                        const double u = u0 + (u1 - u0) * i / (nu - 1), v = v0 + (v1 - v0) * j / (nv - 1);
                        const SurfaceDerivatives d = s.evaluate(u, v, 1);
                        const Vec3 normal = s.normal(u, v);
                        for (int k = 0; k < 3; ++k) {
                            p(i, j, k) = d.s[k];
                            n(i, j, k) = normal[k];
                        }
                    }
            }
            return py::make_tuple(points, normals);
        }, py::arg("nu"), py::arg("nv"),
           "Exact points and unit normals on an nu x nv grid evenly spaced over the domain (two (nu, nv, 3) "
           "arrays), for displays that shade per pixel.")
        .def("curvature", [](const BSplineSurface& s, double u, double v) { return curvatureDict(s.curvature(u, v)); },
             py::arg("u"), py::arg("v"), "Normal curvature along u and v, principal (min, max), mean and Gaussian.");

    py::class_<MaterialMap>(m, "MaterialMap", "Material density over (u, v) in [0, 1]^2 with bilinear lookup; 1x1 is uniform.")
        .def_property_readonly("name", &MaterialMap::name)
        .def_property_readonly("uniform", &MaterialMap::uniform)
        .def_property_readonly("shape", [](const MaterialMap& mm) { return std::make_pair(mm.rows(), mm.cols()); })
        .def_property_readonly("values", [](const MaterialMap& mm) {
            auto storage = mm.storage();
            auto* keep = new std::shared_ptr<Eigen::VectorXd>(storage);  // owned by the capsule
            py::capsule owner(keep, [](void* p) { delete static_cast<std::shared_ptr<Eigen::VectorXd>*>(p); });
            return view(storage->data(), {mm.rows(), mm.cols()}, owner);
        }, "Read-only (rows, cols) view of the grid (stays valid after a resize, then stale).")
        .def_property_readonly("version", &MaterialMap::version)
        .def("at", &MaterialMap::at, py::arg("u"), py::arg("v"), "Bilinear value at normalised (u, v).")
        .def("set_uniform", &MaterialMap::setUniform, py::arg("value"))
        .def("set_values", [](MaterialMap& mm, py::array_t<double, py::array::c_style | py::array::forcecast> a) {
            if (a.ndim() != 2) throw std::invalid_argument("values: expected a 2D array");
            mm.setValues(static_cast<int>(a.shape(0)), static_cast<int>(a.shape(1)),
                         Eigen::Map<const Eigen::VectorXd>(a.data(), a.size()));
        }, py::arg("values"))
        .def("resize", &MaterialMap::resize, py::arg("rows"), py::arg("cols"), "Resample onto a rows x cols grid.")
        .def("dab", [](MaterialMap& mm, std::pair<double, double> uv, double radius, double value, const std::string& falloff,
                       double strength) { mm.dab(uv.first, uv.second, radius, value, falloffFrom(falloff), strength); },
             py::arg("uv"), py::arg("radius"), py::arg("value"), py::arg("falloff") = "spherical", py::arg("strength") = 0.5,
             "Airbrush: move values within radius of uv toward value by strength * falloff.");

    py::class_<Tool>(m, "Tool", "A sculpting tool; the reaction on the cursor is minus the sum of its forces on the surface.")
        .def_property_readonly("name", &Tool::name)
        .def_property_readonly("grabbed", &Tool::grabbed)
        .def_property_readonly("anchor", &Tool::anchor, "Mesh index the tool holds, -1 if none")
        .def_property("max_force", [](const Tool& t) { return t.limits.maxForce; },
                      [](Tool& t, double v) { checkParam(v, "max_force"); t.limits.maxForce = v; })
        .def_property("ramp_time", [](const Tool& t) { return t.limits.rampTime; },
                      [](Tool& t, double v) { checkParam(v, "ramp_time", true); t.limits.rampTime = v; });
    {
        py::class_<RopeTool, Tool> c(m, "RopeTool");
        positive(c, "stiffness", &RopeTool::stiffness, "force per length below the threshold");
        positive(c, "stiff_stiffness", &RopeTool::stiffStiffness, "force per length past the threshold");
        positive(c, "threshold", &RopeTool::threshold, "extension beyond rest length where the rope turns stiff", true);
        positive(c, "reel_time", &RopeTool::reelTime, "seconds for the rest length to reel in to zero", true);
        c.def_property_readonly("rest_length", &RopeTool::restLength);
    }
    {
        py::class_<MagnetTool, Tool> c(m, "MagnetTool");
        positive(c, "radius", &MagnetTool::radius, "selection radius");
        positive(c, "stiffness", &MagnetTool::stiffness, "spring stiffness per point");
        c.def_property("falloff", [](const MagnetTool& t) { return falloffName(t.falloff); },
                       [](MagnetTool& t, const std::string& s) { t.falloff = falloffFrom(s); });
        c.def_property_readonly("selected", &MagnetTool::selected);
    }
    {
        py::class_<OrientationTool, Tool> c(m, "OrientationTool");
        positive(c, "stiffness", &OrientationTool::stiffness, "stiffness of the five springs");
    }
    {
        py::class_<SmoothTool, Tool> c(m, "SmoothTool");
        positive(c, "radius", &SmoothTool::radius, "brush radius");
        positive(c, "strength", &SmoothTool::strength, "fairing force per unit of U^3 x");
        c.def_property("falloff", [](const SmoothTool& t) { return falloffName(t.falloff); },
                       [](SmoothTool& t, const std::string& s) { t.falloff = falloffFrom(s); });
    }

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
               if (mesh.first < 2 || mesh.second < 2) throw std::invalid_argument("mesh: need at least 2x2 samples");
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
        .def_property_readonly("external_forces", [](py::object self) {
            auto& s = self.cast<DynamicSurface&>();
            return view(s.externalForces().data(), {s.g(), s.h(), 3}, self);
        })
        .def_property_readonly("size", &DynamicSurface::size, "Diagonal of the initial mesh's bounding box")
        .def_property("reference", &DynamicSurface::reference, &DynamicSurface::setReference,
                      "(size, spacing_u, spacing_v) of the initial mesh; they scale tolerances and tools")
        .def("set_poles", [](DynamicSurface& s, py::array_t<double, py::array::c_style | py::array::forcecast> p) {
            s.setPoles(pointsFrom(p, s.poles().rows(), "poles"));
        }, py::arg("poles"), "Replace the poles (velocities zeroed, rest lengths kept).")
        .def("set_velocities", [](DynamicSurface& s, py::array_t<double, py::array::c_style | py::array::forcecast> v) {
            s.setVelocities(pointsFrom(v, s.poles().rows(), "velocities"));
        }, py::arg("velocities"))
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
        .def_property_readonly("spring_count", [](const DynamicSurface& s) { return s.springs().size(); })
        .def_property_readonly("rest_lengths", [](const DynamicSurface& s) { return s.springs().rest(); })
        .def("set_rest_lengths", [](DynamicSurface& s, const std::vector<double>& r) { s.springs().setRest(r); }, py::arg("rest"))
        .def("relax", [](DynamicSurface& s) { s.springs().resetRest(s.mesh()); s.wake(); },
             "Make the current shape the rest shape (rest lengths from the current mesh).")
        .def("set_stiffness_law", [](DynamicSurface& s, const std::string& kind, double scale) { s.springs().law = makeLaw(kind, scale); },
             py::arg("kind"), py::arg("scale") = 1.0, "linear, cubic (g = x + x^3/s^2) or saturating (g = s tanh(x/s)) spring force")
        .def_property_readonly("stiffness_law", [](const DynamicSurface& s) { return std::make_pair(lawName(s.springs().law.kind), s.springs().law.scale); })
        .def("set_damping_law", [](DynamicSurface& s, const std::string& kind, double scale) { s.dampingLaw = makeLaw(kind, scale); s.wake(); },
             py::arg("kind"), py::arg("scale") = 1.0, "damping multiplied by g(F)/F of each point's spring-force magnitude F")
        .def_property_readonly("damping_law", [](const DynamicSurface& s) { return std::make_pair(lawName(s.dampingLaw.kind), s.dampingLaw.scale); })
        .def("set_plasticity", [](DynamicSurface& s, bool enabled, double yieldStrain, double rate) {
            checkParam(yieldStrain, "yield_strain", true);
            checkParam(rate, "rate", true);
            s.springs().plasticity = {enabled, yieldStrain, rate};
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
        .def_readwrite("max_point_force", &DynamicSurface::maxPointForce)
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
            const ConstraintKind k = constraintFrom(kind);
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
                d["id"] = c.id; d["kind"] = constraintName(c.kind); d["index"] = c.point; d["stiffness"] = c.stiffness;
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
            c.kind = constraintFrom(kind);
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
        .def_readwrite("constraint_stiffness_factor", &DynamicSurface::constraintStiffnessFactor,
                       "default penalty stiffness = factor * mean material stiffness")
        .def("mesh_curvature", [](const DynamicSurface& s, int index, int dir) {
            if (index < 0 || index >= s.g() * s.h()) throw std::invalid_argument("index: out of range");
            const int i = index / s.h(), j = index % s.h();
            if (i < 1 || j < 1 || i > s.g() - 2 || j > s.h() - 2) throw std::invalid_argument("index: must be an interior point");
            if (dir != 0 && dir != 1) throw std::invalid_argument("direction: 0 (u) or 1 (v)");
            return s.constraints().meshCurvature(s.mesh(), index, dir);
        }, py::arg("index"), py::arg("direction"), "Curvature of the circle through a point and its two neighbours along u (0) or v (1)")
        // stepping
        .def_property("integrator", [](const DynamicSurface& s) { return integratorName(s.solver.kind); },
                      [](DynamicSurface& s, const std::string& k) { s.solver.kind = integratorFrom(k); s.wake(); },
                      "explicit (paper eq. 8-9, adaptive halving), implicit (backward Euler, CG) or local_global (default: "
                      "BDF2 by local/global iterations, velocity Verlet where that is provably stable)")
        .def_property("iterations", [](const DynamicSurface& s) { return s.solver.iterations; },
                      [](DynamicSurface& s, int n) { if (n < 1 || n > 1000) throw std::invalid_argument("iterations: 1..1000"); s.solver.iterations = n; })
        .def_property("time_order", [](const DynamicSurface& s) { return s.solver.timeOrder; },
                      [](DynamicSurface& s, int n) { if (n != 1 && n != 2) throw std::invalid_argument("time_order: 1 (backward Euler) or 2 (BDF2)"); s.solver.timeOrder = n; s.wake(); },
                      "local_global's time discretisation: 2 = BDF2 (default, second order), 1 = backward Euler")
        .def_property("explicit_when_stable", [](const DynamicSurface& s) { return s.solver.explicitWhenStable; },
                      [](DynamicSurface& s, bool e) { s.solver.explicitWhenStable = e; s.wake(); },
                      "local_global: take an explicit velocity Verlet step wherever it is provably stable for the "
                      "step (cheaper and more accurate there), the implicit step elsewhere (default on)")
        .def_property("cg_iterations", [](const DynamicSurface& s) { return s.solver.cgIterations; },
                      [](DynamicSurface& s, int n) { if (n < 1 || n > 10000) throw std::invalid_argument("cg_iterations: 1..10000"); s.solver.cgIterations = n; })
        .def_property("acceleration_limit", [](const DynamicSurface& s) { return s.solver.accelerationLimit; },
                      [](DynamicSurface& s, double a) { checkParam(a, "acceleration_limit", true); s.solver.accelerationLimit = a; })
        .def_property("max_halvings", [](const DynamicSurface& s) { return s.solver.maxHalvings; },
                      [](DynamicSurface& s, int n) { if (n < 0 || n > 30) throw std::invalid_argument("max_halvings: 0..30"); s.solver.maxHalvings = n; })
        .def_property("sleep_enabled", [](const DynamicSurface& s) { return s.sleep.enabled; },
                      [](DynamicSurface& s, bool e) { s.sleep.enabled = e; s.wake(); })
        .def_property("sleep_tolerance", [](const DynamicSurface& s) { return s.sleep.tolerance; },
                      [](DynamicSurface& s, double t) { checkParam(t, "sleep_tolerance"); s.sleep.tolerance = t; })
        .def_property("energy_guard", [](const DynamicSurface& s) { return s.energyGuard.enabled; },
                      [](DynamicSurface& s, bool e) { s.energyGuard.enabled = e; s.wake(); },
                      "keep kinetic + potential energy within (1 + energy_slack) x (energy at the last change + work "
                      "put in); runs for explicit, implicit, non-linear laws, curvature constraints and very long steps")
        .def_property("energy_slack", [](const DynamicSurface& s) { return s.energyGuard.slack; },
                      [](DynamicSurface& s, double x) { checkParam(x, "energy_slack", true); s.energyGuard.slack = x; })
        .def_property_readonly("verlet_step_limit", &DynamicSurface::verletStepLimit,
                               "longest step local_global takes by its explicit Verlet branch now (0: never)")
        .def_property_readonly("energy_ceiling", &DynamicSurface::energyCeiling,
                               "the energy guard's ceiling (0 when the guard is not running for this scene)")
        .def_property_readonly("asleep", &DynamicSurface::asleep)
        .def("wake", &DynamicSurface::wake)
        .def("step", [](DynamicSurface& s, double dt, int steps) {
            if (steps < 1) throw std::invalid_argument("steps: must be >= 1");
            if (!(dt >= kMinDt) || !std::isfinite(dt)) throw std::invalid_argument("dt: must be finite and >= 1e-9 s");
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
        .def_property_readonly("work_done", &DynamicSurface::workDone, "work of external and tool forces so far")
        .def("kinetic_energy", &DynamicSurface::kineticEnergy)
        .def("potential_energy", &DynamicSurface::potentialEnergy, "springs plus penalty terms")
        .def("potential_gradient", [](DynamicSurface& s) {
            const Points& g = s.potentialGradient();
            const auto [nu, nv] = std::make_pair(s.surface().nu(), s.surface().nv());
            py::array_t<double> out({nu, nv, 3});
            std::copy(g.data(), g.data() + g.size(), out.mutable_data());
            return out;
        }, "Gradient of potential_energy() with respect to the poles (nu, nv, 3): -A^T f(d), springs and constraints")
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

    bindRuntime(m);
}
