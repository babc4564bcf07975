// BSplineSurface: construction, evaluation, curvature and exact grids.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstdint>
#include <algorithm>
#include <optional>
#include <thread>
#include <vector>

#include "geometry/falloff.hpp"
#include "bindings.hpp"
#include "geometry/bspline_surface.hpp"
#include "geometry/point_tree.hpp"
#include "geometry/surface_projection.hpp"
#include "convert.hpp"

namespace py = pybind11;

namespace hs {
namespace {

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

// Runs body(begin, end) over [0, n) in as many slices as the machine has cores (one below 20000:
// a thread costs more than it saves), each on its own thread: the queries are independent and
// read-only, each slice writes its own rows.
template <class Body>
void slices(py::ssize_t n, Body&& body) {
    const py::ssize_t cores = std::max(1u, std::min(8u, std::thread::hardware_concurrency()));
    const py::ssize_t parts = n < 20000 ? 1 : cores;
    std::vector<std::thread> threads;
    for (py::ssize_t k = 1; k < parts; ++k) threads.emplace_back(body, n * k / parts, n * (k + 1) / parts);
    body(py::ssize_t{0}, n / parts);
    for (std::thread& t : threads) t.join();
}

// An (n, 3) array of points (n >= 0) named `name`.
Points cloudFrom(const DoubleArray& a, const char* name) {
    if (a.ndim() != 2 || a.shape(1) != 3) throw std::invalid_argument(std::string(name) + ": expected an (n, 3) array");
    return pointsFrom(a, static_cast<Eigen::Index>(a.shape(0)), name);
}

}  // namespace

void bindGeometry(py::module_& m) {
    m.attr("MAX_DEGREE") = kMaxDegree;
    m.attr("FALLOFFS") = namesOf(kFalloffNames);
    py::class_<BSplineSurface>(m, "BSplineSurface", "Tensor-product B-spline surface, rational with fixed weights if weights are given.")
        .def(py::init([](DoubleArray poles, std::pair<int, int> degree,
                         std::optional<std::vector<double>> knotsU, std::optional<std::vector<double>> knotsV,
                         std::optional<DoubleArray> weights) {
                 if (poles.ndim() != 3 || poles.shape(2) != 3)
                     throw std::invalid_argument("poles: expected an array of shape (nu, nv, 3)");
                 const int nu = static_cast<int>(poles.shape(0)), nv = static_cast<int>(poles.shape(1));
                 Points P = pointsFrom(poles, static_cast<Eigen::Index>(nu) * nv, "poles");
                 Eigen::VectorXd w;
                 if (weights) {
                     if (weights->size() != static_cast<py::ssize_t>(nu) * nv)
                         throw std::invalid_argument("weights: expected shape (nu, nv)");
                     w = Eigen::Map<const Eigen::VectorXd>(weights->data(), weights->size());
                 }
                 return BSplineSurface(nu, nv, degree.first, degree.second,
                                       knotsU ? *knotsU : clampedUniformKnots(nu, degree.first, "poles"),
                                       knotsV ? *knotsV : clampedUniformKnots(nv, degree.second, "poles"), std::move(P),
                                       std::move(w));
             }),
             py::arg("poles"), py::arg("degree") = std::make_pair(3, 3), py::arg("knots_u") = py::none(),
             py::arg("knots_v") = py::none(), py::arg("weights") = py::none(),
             "poles: (nu, nv, 3); degree: (p, q) in 1..5; knots: full non-decreasing vectors (clamped uniform by default); "
             "weights: (nu, nv) > 0 or None.")
        .def_static("plane", [](std::pair<int, int> controls, std::pair<int, int> degree, std::pair<double, double> size) {
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
            BSplineSurface::checkGridSize(nu, nv);  // before allocating
            py::array_t<double> points({nu, nv, 3}), normals({nu, nv, 3});
            {
                py::gil_scoped_release release;
                s.grid(nu, nv, points.mutable_data(), normals.mutable_data());
            }
            return py::make_tuple(points, normals);
        }, py::arg("nu"), py::arg("nv"),
           "Exact points and unit normals on an nu x nv grid evenly spaced over the domain (two (nu, nv, 3) "
           "arrays), for displays that shade per pixel.")
        .def("project", [](const BSplineSurface& s, DoubleArray points, int samplesPerSpan, std::optional<DoubleArray> start) {
            const SurfaceProjection projection(s, samplesPerSpan);
            const Points x = cloudFrom(points, "points");
            if (!withinRange(x)) throw std::invalid_argument("points: must be finite and within +-1e9");
            const py::ssize_t n = x.rows();
            if (start && (start->ndim() != 2 || start->shape(0) != n || start->shape(1) != 2))
                throw std::invalid_argument("start: expected an (n, 2) array of (u, v), one per point");
            const double* from = start ? start->data() : nullptr;
            py::array_t<double> uv({n, py::ssize_t{2}}), foot({n, py::ssize_t{3}}), normal({n, py::ssize_t{3}}), dist(n);
            py::array_t<bool> beyond(n);
            {
                py::gil_scoped_release release;
                double *a = uv.mutable_data(), *f = foot.mutable_data(), *nn = normal.mutable_data(), *d = dist.mutable_data();
                bool* b = beyond.mutable_data();
                slices(n, [&](py::ssize_t begin, py::ssize_t end) {
                    for (py::ssize_t i = begin; i < end; ++i) {
                        const SurfaceFoot r = from ? projection.project(x.row(i).transpose(), from[2 * i], from[2 * i + 1])
                                                   : projection.project(x.row(i).transpose());
                        a[2 * i] = r.u, a[2 * i + 1] = r.v;
                        for (int c = 0; c < 3; ++c) f[3 * i + c] = r.point[c], nn[3 * i + c] = r.normal[c];
                        d[i] = r.distance, b[i] = r.beyondEdge;
                    }
                });
            }
            py::dict out;
            out["uv"] = uv; out["foot"] = foot; out["normal"] = normal; out["distance"] = dist; out["beyond_edge"] = beyond;
            return out;
        }, py::arg("points"), py::arg("samples_per_span") = SurfaceProjection::kDefaultSamples, py::arg("start") = py::none(),
           "The closest point on the surface to each of points ((n, 3)), from start ((n, 2) parameters: feet from "
           "before the surface moved a little) where given: a dict of uv (n, 2), foot (n, 3), normal "
           "(n, 3) (unit, du x dv), distance (n,) (signed: negative behind the normal) and beyond_edge (n,) (the "
           "foot is on the domain's edge and the point lies beyond it).")
        .def("curvature", [](const BSplineSurface& s, double u, double v) { return curvatureDict(s.curvature(u, v)); },
             py::arg("u"), py::arg("v"), "Normal curvature along u and v, principal (min, max), mean and Gaussian.");

    py::class_<PointTree, std::shared_ptr<PointTree>>(m, "PointTree", "Nearest-point queries over a fixed cloud of 3D points (a k-d tree).")
        .def(py::init([](DoubleArray points) { return PointTree(cloudFrom(points, "points")); }), py::arg("points"),
             "points: (n, 3), n >= 1, finite.")
        .def_property_readonly("size", &PointTree::size)
        .def("nearest", [](const PointTree& t, DoubleArray queries) {
            const Points x = cloudFrom(queries, "queries");
            if (!withinRange(x)) throw std::invalid_argument("queries: must be finite and within +-1e9");
            const py::ssize_t n = x.rows();
            py::array_t<std::int64_t> index(n);
            py::array_t<double> dist(n);
            {
                py::gil_scoped_release release;
                std::int64_t* ix = index.mutable_data();
                double* d = dist.mutable_data();
                slices(n, [&](py::ssize_t begin, py::ssize_t end) {
                    for (py::ssize_t i = begin; i < end; ++i) {
                        double d2 = 0;
                        ix[i] = t.nearest(x.row(i).transpose(), d2);
                        d[i] = std::sqrt(d2);
                    }
                });
            }
            return py::make_tuple(index, dist);
        }, py::arg("queries"), "For each of queries ((n, 3)): the index of the nearest point and its distance.");
}

}  // namespace hs
