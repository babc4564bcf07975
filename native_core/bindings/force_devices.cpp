// The 3-DOF force devices: Haply's Inverse3 through its service, the Novint Falcon over USB, 3D Systems' Touch/Phantom (OpenHaptics) and
// Force Dimension's (DHD) through their vendors' libraries, what is attached, and the table of
// device limits. Opening and homing wait: they release the GIL.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <optional>
#include <stdexcept>

#include "bindings.hpp"
#include "devices/device_limits.hpp"
#include "devices/vendor/dhd_device.hpp"
#include "devices/falcon/falcon_device.hpp"
#include "devices/falcon/falcon_usb.hpp"
#include "devices/haply/haply_device.hpp"
#include "devices/vendor/openhaptics_device.hpp"

namespace py = pybind11;

namespace hs {
namespace {

DeviceMapping mappingOf(const Vec3& origin, double scale, double forceScale) {
    DeviceMapping m;
    m.origin = origin;
    m.scale = scale;
    m.forceScale = forceScale;
    m.validate();
    return m;
}

VendorDeviceSettings vendorSettings(std::optional<std::vector<std::string>> library, const Vec3& origin, double scale,
                                    double forceScale, double maxForce, double rate) {
    VendorDeviceSettings s;
    s.mapping = mappingOf(origin, scale, forceScale);
    if (library) s.library = *library;
    s.maxForce = maxForce;
    s.rateHz = rate;
    s.validate();
    return s;
}

py::dict probeDict(const VendorProbe& p) {
    py::dict d;
    d["loaded"] = p.loaded;
    d["library"] = p.library;
    d["attached"] = p.attached;
    d["model"] = p.model;
    d["why"] = p.why;
    return d;
}

// The arguments every force device takes, with the workbench's units (mm, kg, s: mN).
#define HS_MAPPING_ARGS                                                                              \
    py::arg("origin") = Vec3(0, 0, 0), py::arg("scale") = 1.0, py::arg("force_scale") = 1e-3,        \
        py::arg("max_force") = 0.0, py::arg("rate") = kDefaultHapticRate
}  // namespace

void bindForceDevices(py::module_& m) {
    m.def("usb_falcons", [](std::optional<std::vector<std::string>> library) {
        py::list out;
        const auto usb = usb::Library::load(library ? *library : std::vector<std::string>{});
        const auto found = falcon::attachedFalcons(*usb);
        for (std::size_t i = 0; i < found.size(); ++i) {
            const auto& f = found[i];
            py::dict d;
            d["bus"] = f.bus;
            d["address"] = f.address;
            d["openable"] = f.openable;
            d["why"] = f.why;
            d["firmware_running"] = false;
            if (f.openable) {
                try {  // claims it for a moment: a Falcon in use says so
                    py::gil_scoped_release release;
                    falcon::UsbTransport link(usb, static_cast<int>(i));
                    const bool running = link.firmwareRunning();
                    py::gil_scoped_acquire acquire;
                    d["firmware_running"] = running;
                } catch (const std::runtime_error& e) {
                    d["openable"] = false;
                    d["why"] = e.what();
                }
            }
            out.append(d);
        }
        return out;
    }, py::arg("library") = py::none(), "The Falcons on USB (0403:cb48): whether each can be opened (and why not) and "
                                        "whether its firmware runs; RuntimeError when libusb is missing.");
    m.def("openhaptics_probe", [](std::optional<std::vector<std::string>> library) {
        VendorProbe p;
        {
            py::gil_scoped_release release;
            p = OpenHapticsDevice::probe(library ? *library : std::vector<std::string>{});
        }
        return probeDict(p);
    }, py::arg("library") = py::none(), "OpenHaptics: library loaded, default device attached and its model, or why not.");
    m.def("dhd_probe", [](std::optional<std::vector<std::string>> library) {
        return probeDict(DhdDevice::probe(library ? *library : std::vector<std::string>{}));
    }, py::arg("library") = py::none(), "Force Dimension DHD: library loaded, devices attached, or why not.");
    m.def("device_limits", [] {
        py::list out;
        for (const DeviceLimits& row : deviceLimitsTable()) {
            py::dict d;
            d["model"] = row.model;
            d["rated_force"] = row.ratedForce;
            d["damping"] = row.damping;
            d["mass"] = row.mass;
            d["rates"] = std::vector<double>{row.servoRates[0], row.servoRates[1]};
            d["max_stiffness"] = std::vector<double>{passiveStiffnessFor(row, row.servoRates[0]), passiveStiffnessFor(row, row.servoRates[1])};
            d["source"] = row.source;
            out.append(d);
        }
        return out;
    }, "The force devices' limits (N, N s/m, kg, Hz, N/m at each rate) and where they come from.");

    m.def("haply_devices", [](const std::string& host, int port, double timeout) {
        std::vector<haply::Inverse3Info> found;
        {
            py::gil_scoped_release release;
            found = HaplyDevice::discover(host, port, timeout);
        }
        py::list out;
        for (const auto& d : found) {
            py::dict e;
            e["device_id"] = d.deviceId;
            e["ready"] = d.ready;
            e["in_use"] = d.inUse;
            e["calibrated"] = d.calibrated;
            out.append(e);
        }
        return out;
    }, py::arg("host") = "127.0.0.1", py::arg("port") = 10001, py::arg("timeout") = 1.0,
       "The Inverse3s Haply's Inverse Service lists; RuntimeError when it cannot be reached.");

    py::class_<HaplyDevice, Device, std::shared_ptr<HaplyDevice>>(m, "HaplyDevice",
        "A Haply Inverse3 through the Inverse Service (WebSocket JSON); the grip's position at start() maps to origin.")
        .def(py::init([](const std::string& host, int port, const std::string& deviceId, const Vec3& origin, double scale,
                         double forceScale, double maxForce, double rate) {
                 HaplySettings s;
                 s.mapping = mappingOf(origin, scale, forceScale);
                 s.host = host;
                 s.port = port;
                 s.deviceId = deviceId;
                 s.maxForce = maxForce;
                 s.rateHz = rate;
                 s.validate();
                 return std::make_shared<HaplyDevice>(s);
             }), py::arg("host") = "127.0.0.1", py::arg("port") = 10001, py::arg("device_id") = "", HS_MAPPING_ARGS)
        .def("start", &HaplyDevice::start, py::call_guard<py::gil_scoped_release>())
        .def("stop", &HaplyDevice::stop, py::call_guard<py::gil_scoped_release>())
        .def("set_force", [](HaplyDevice& d, const Vec3& f) { d.setForce(f); }, py::arg("force"))
        .def_property_readonly("device_id", &HaplyDevice::deviceId)
        .def_property_readonly("updates", &HaplyDevice::updates)
        .def_property_readonly("malformed", &HaplyDevice::malformed);

    py::class_<FalconDevice, Device, std::shared_ptr<FalconDevice>>(m, "FalconDevice",
        "A Novint Falcon on USB (libusb loaded at run time); its firmware is loaded from `firmware` if it is not running.")
        .def(py::init([](int index, const std::string& firmware, std::optional<std::vector<std::string>> library,
                         const Vec3& origin, double scale, double forceScale, double maxForce, double rate) {
                 FalconSettings s;
                 s.mapping = mappingOf(origin, scale, forceScale);
                 if (maxForce > 0) s.maxForce = maxForce;
                 s.rateHz = rate;
                 s.validate();
                 std::shared_ptr<falcon::UsbTransport> link;
                 {
                     py::gil_scoped_release release;
                     link = falcon::openFalconUsb(usb::Library::load(library ? *library : std::vector<std::string>{}), index, firmware);
                 }
                 return std::make_shared<FalconDevice>(link, s);
             }), py::arg("index") = 0, py::arg("firmware") = "", py::arg("library") = py::none(), HS_MAPPING_ARGS)
        .def("start", &FalconDevice::start, py::call_guard<py::gil_scoped_release>(), "Homes it (move the grip in and out).")
        .def("stop", &FalconDevice::stop, py::call_guard<py::gil_scoped_release>())
        .def("set_force", [](FalconDevice& d, const Vec3& f) { d.setForce(f); }, py::arg("force"))
        .def_property_readonly("frames", &FalconDevice::frames);

    py::class_<OpenHapticsDevice, Device, std::shared_ptr<OpenHapticsDevice>>(m, "OpenHapticsDevice",
        "3D Systems Touch / Phantom through OpenHaptics (libHD.so, loaded at run time).")
        .def(py::init([](std::optional<std::vector<std::string>> library, const Vec3& origin, double scale, double forceScale,
                         double maxForce, double rate) {
                 return std::make_shared<OpenHapticsDevice>(vendorSettings(library, origin, scale, forceScale, maxForce, rate));
             }), py::arg("library") = py::none(), HS_MAPPING_ARGS)
        .def("start", &OpenHapticsDevice::start, py::call_guard<py::gil_scoped_release>())
        .def("stop", &OpenHapticsDevice::stop, py::call_guard<py::gil_scoped_release>())
        .def("set_force", [](OpenHapticsDevice& d, const Vec3& f) { d.setForce(f); }, py::arg("force"))
        .def_property_readonly("model", &OpenHapticsDevice::model)
        .def_property_readonly("frames", &OpenHapticsDevice::frames);

    py::class_<DhdDevice, Device, std::shared_ptr<DhdDevice>>(m, "DhdDevice",
        "A Force Dimension device through the DHD SDK (libdhd.so, loaded at run time).")
        .def(py::init([](std::optional<std::vector<std::string>> library, const Vec3& origin, double scale, double forceScale,
                         double maxForce, double rate) {
                 return std::make_shared<DhdDevice>(vendorSettings(library, origin, scale, forceScale, maxForce, rate));
             }), py::arg("library") = py::none(), HS_MAPPING_ARGS)
        .def("start", &DhdDevice::start, py::call_guard<py::gil_scoped_release>())
        .def("stop", &DhdDevice::stop, py::call_guard<py::gil_scoped_release>())
        .def("set_force", [](DhdDevice& d, const Vec3& f) { d.setForce(f); }, py::arg("force"))
        .def_property_readonly("model", &DhdDevice::model);
}

}  // namespace hs
