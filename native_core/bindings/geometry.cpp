// BSplineSurface: construction, evaluation, curvature and exact grids.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <optional>

#include "geometry/falloff.hpp"
#include "bindings.hpp"
#include "geometry/bspline_surface.hpp"
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
        .def("curvature", [](const BSplineSurface& s, double u, double v) { return curvatureDict(s.curvature(u, v)); },
             py::arg("u"), py::arg("v"), "Normal curvature along u and v, principal (min, max), mean and Gaussian.");
}

}  // namespace hs
