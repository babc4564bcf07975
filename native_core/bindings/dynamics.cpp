// MaterialMap: the mass, damping and stiffness maps over (u, v).
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <memory>

#include "dynamics/response_law.hpp"
#include "bindings.hpp"
#include "convert.hpp"
#include "dynamics/material_map.hpp"
#include "common/names.hpp"

namespace py = pybind11;

namespace hs {

void bindDynamics(py::module_& m) {
    m.attr("LAWS") = namesOf(kLawNames);
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
        .def("set_values", [](MaterialMap& mm, DoubleArray a) {
            if (a.ndim() != 2) throw std::invalid_argument("values: expected a 2D array");
            mm.setValues(static_cast<int>(a.shape(0)), static_cast<int>(a.shape(1)),
                         Eigen::Map<const Eigen::VectorXd>(a.data(), a.size()));
        }, py::arg("values"))
        .def("resize", &MaterialMap::resize, py::arg("rows"), py::arg("cols"), "Resample onto a rows x cols grid.")
        .def("dab", [](MaterialMap& mm, std::pair<double, double> uv, double radius, double value, const std::string& falloff,
                       double strength) { mm.dab(uv.first, uv.second, radius, value, fromName(kFalloffNames, falloff, "falloff"), strength); },
             py::arg("uv"), py::arg("radius"), py::arg("value"), py::arg("falloff") = "spherical", py::arg("strength") = 0.5,
             "Airbrush: move values within radius of uv toward value by strength * falloff.");
}

}  // namespace hs
