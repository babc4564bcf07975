// The device interface the haptic loop reads (Device) and the devices fed from outside the core:
// a recorded replay and an external device (the GUI's mouse, scripts).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "convert.hpp"
#include "devices/external_device.hpp"
#include "devices/replay_device.hpp"

namespace py = pybind11;

namespace hs {
namespace {

py::dict sampleDict(const DeviceSample& s) {
    py::dict d;
    d["position"] = Vec3(s.position);
    d["orientation"] = std::vector<double>{s.orientation.w(), s.orientation.x(), s.orientation.y(), s.orientation.z()};
    d["buttons"] = s.buttons;
    d["valid"] = s.valid;
    return d;
}
}  // namespace

void bindDevices(py::module_& m) {
    py::class_<Device, std::shared_ptr<Device>>(m, "Device", "A cursor device the haptic loop reads and renders forces to.")
        .def_property_readonly("name", &Device::name)
        .def_property_readonly("capabilities", [](const Device& d) {
            const DeviceCaps c = d.caps();
            py::dict out;
            out["dof"] = c.dof;
            out["force_output"] = c.forceOutput;
            out["rate_hz"] = c.rateHz;
            out["max_force"] = c.maxForce;
            out["max_stiffness"] = c.maxStiffness;
            return out;
        })
        .def("sample", [](Device& d, double t) {
            DeviceSample s;
            if (!d.sample(t, s)) throw std::runtime_error("device lost");
            return sampleDict(s);
        }, py::arg("t"), "The cursor at session time t (for tests and tools; the haptic loop calls it natively).");

    py::class_<ReplayDevice, Device, std::shared_ptr<ReplayDevice>>(m, "NativeReplayDevice",
                                                                 "C++ side of HapticSculpt.ReplayDevice (same interpolation).")
        .def(py::init([](std::vector<double> t, py::array_t<double, py::array::c_style | py::array::forcecast> xyz,
                         py::array_t<double, py::array::c_style | py::array::forcecast> quat, std::vector<std::uint32_t> buttons) {
                 const auto n = static_cast<Eigen::Index>(t.size());
                 if (xyz.ndim() != 2 || xyz.shape(0) != n || xyz.shape(1) != 3) throw std::invalid_argument("xyz: expected (n, 3)");
                 if (quat.ndim() != 2 || quat.shape(0) != n || quat.shape(1) != 4) throw std::invalid_argument("quat: expected (n, 4)");
                 Points p = Eigen::Map<const Points>(xyz.data(), n, 3);
                 Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> q =
                     Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>>(quat.data(), n, 4);
                 return std::make_shared<ReplayDevice>(std::move(t), std::move(p), std::move(q), std::move(buttons));
             }), py::arg("t"), py::arg("xyz"), py::arg("quat"), py::arg("buttons"))
        .def_property_readonly("duration", &ReplayDevice::duration);

    py::class_<ExternalDevice, Device, std::shared_ptr<ExternalDevice>>(m, "ExternalDevice",
                                                                     "A cursor pushed from outside (the mouse in the 3D view).")
        .def(py::init<std::string>(), py::arg("name") = "mouse")
        .def("push", [](ExternalDevice& d, const std::vector<double>& position, const std::vector<double>& orientation,
                        std::uint32_t buttons) {
            if (position.size() != 3 || orientation.size() != 4) throw std::invalid_argument("position/orientation: expected 3 and 4 numbers");
            DeviceSample s;
            s.position = Vec3(position[0], position[1], position[2]);
            s.orientation = Eigen::Quaterniond(orientation[0], orientation[1], orientation[2], orientation[3]);
            s.buttons = buttons;
            s.valid = true;
            d.push(s);
        }, py::arg("position"), py::arg("orientation") = std::vector<double>{1, 0, 0, 0}, py::arg("buttons") = 0)
        .def("lose", &ExternalDevice::lose, "Mark the device lost: its session stops.")
        .def_property_readonly("last_force", &ExternalDevice::lastForce);
}

}  // namespace hs
