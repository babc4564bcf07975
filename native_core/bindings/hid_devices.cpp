// The C++ devices: HID discovery, report descriptors, the SpaceMouse, HID PID force feedback.
// Calls that wait (stop) release the GIL.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>

#include "bindings.hpp"
#include "convert.hpp"
#include "devices/hid/hid_report_descriptor.hpp"
#include "devices/hid/hidapi_transport.hpp"
#include "devices/hid/pid_emulator.hpp"
#include "devices/hid/pid_force.hpp"
#include "devices/hid/recorded_transport.hpp"
#include "devices/hid/spacemouse.hpp"

namespace py = pybind11;

namespace hs {
namespace {

py::dict stateDict(const SpaceMouseState& s) {
    py::dict d;
    d["axes"] = std::vector<int>(s.axes, s.axes + 6);
    d["buttons"] = s.buttons;
    d["reports"] = s.reports;
    d["malformed"] = s.malformed;
    d["unknown"] = s.unknown;
    d["ignored"] = s.ignored;
    d["combined_layout"] = s.combinedLayout;
    return d;
}

py::dict infoDict(const HidInfo& i) {
    py::dict d;
    d["vendor_id"] = i.vendorId;
    d["product_id"] = i.productId;
    d["name"] = i.name;
    d["path"] = i.path;
    d["usage_page"] = i.usagePage;
    d["usage"] = i.usage;
    return d;
}

HidRecording loadRecording(const std::string& path) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) throw std::invalid_argument("recording: cannot open " + path);
    std::string text;
    char buf[4096];
    std::size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) text.append(buf, n);
    std::fclose(f);
    return parseHidRecording(text);
}

// The system's HID interfaces through hidapi.
std::vector<HidInfo> hidInterfaces() { return enumerateHid(); }
std::unique_ptr<HidTransport> openHid(const std::string& path) { return std::make_unique<HidapiTransport>(path); }
}  // namespace

void bindHidDevices(py::module_& m) {
    m.def("hid_devices", [] {
        py::list out;
        for (const HidInfo& i : hidInterfaces()) {
            py::dict d = infoDict(i);
            const SpaceMouseModel* model = findSpaceMouse(i.vendorId, i.productId);
            d["spacemouse"] = model ? py::str(model->name) : py::object(py::none());
            out.append(d);
        }
        return out;
    }, "Every HID interface hidapi (hidraw) sees, with the SpaceMouse model name where known.");
    m.def("spacemouse_models", [] {
        py::list out;
        for (const auto& mm : spaceMouseModels()) out.append(py::make_tuple(mm.vendorId, mm.productId, mm.name));
        return out;
    });
    m.def("parse_report_descriptor", [](const py::bytes& data) {
        const std::string raw = data;
        const HidReportLayout l = parseReportDescriptor(std::vector<std::uint8_t>(raw.begin(), raw.end()));
        py::list out;
        for (const HidField& f : l.fields) {
            py::dict d;
            d["type"] = f.type == ReportType::Input ? "input" : f.type == ReportType::Output ? "output" : "feature";
            d["report_id"] = f.reportId;
            d["usage_page"] = f.usagePage;
            d["usages"] = f.usages;
            d["bit_offset"] = f.bitOffset;
            d["size"] = f.size;
            d["count"] = f.count;
            d["logical_min"] = f.logicalMin;
            d["logical_max"] = f.logicalMax;
            d["variable"] = f.variable;
            d["constant"] = f.constant;
            d["collections"] = f.collections;
            out.append(d);
        }
        return out;
    }, py::arg("descriptor"), "Fields of a HID report descriptor; ValueError for malformed input.");

    py::class_<SpaceMouseParser>(m, "SpaceMouseParser", "SpaceMouse report parser (both layouts, buttons).")
        .def(py::init<>())
        .def("feed", [](SpaceMouseParser& p, const py::bytes& report) {
            const std::string r = report;
            return p.feed(reinterpret_cast<const std::uint8_t*>(r.data()), r.size());
        }, py::arg("report"), "Feed one input report (ID byte first); True if axes or buttons changed.")
        .def_property_readonly("state", [](const SpaceMouseParser& p) { return stateDict(p.state()); });

    py::class_<HidTransport, std::shared_ptr<HidTransport>>(m, "HidTransport")
        .def_property_readonly("info", [](const HidTransport& t) { return infoDict(t.info()); });
    py::class_<PidEmulator, HidTransport, std::shared_ptr<PidEmulator>>(m, "PidEmulator",
        "An emulated HID PID force-feedback device (3 axes) for tests.")
        .def(py::init<int>(), py::arg("pool_size") = 8)
        .def("effects", [](const PidEmulator& e) {
            py::list out;
            for (const auto& x : e.effects()) {
                py::dict d;
                d["allocated"] = x.allocated; d["running"] = x.running; d["constant"] = x.constant;
                d["axes_mask"] = x.axesMask; d["magnitude"] = x.magnitude; d["duration"] = x.duration;
                out.append(d);
            }
            return out;
        })
        .def_property_readonly("actuators_enabled", &PidEmulator::actuatorsEnabled)
        .def_property_readonly("stop_all_count", &PidEmulator::stopAllCount)
        .def_property_readonly("malformed_reports", &PidEmulator::malformedReports)
        .def("unplug", &PidEmulator::unplug);

    py::class_<PidForceDriver, std::shared_ptr<PidForceDriver>>(m, "PidForceDriver",
        "HID PID constant-force output; layout from the device's report descriptor.")
        .def(py::init([](py::object transport, double fullScaleForce) {
                 std::shared_ptr<HidTransport> t;
                 if (py::isinstance<py::str>(transport)) t = openHid(transport.cast<std::string>());
                 else t = transport.cast<std::shared_ptr<HidTransport>>();
                 PidSettings s;
                 s.fullScaleForce = fullScaleForce;
                 return std::make_shared<PidForceDriver>(t, s);
             }), py::arg("transport"), py::arg("full_scale_force") = 1000.0,
             "transport: a hidraw path or a HidTransport (e.g. PidEmulator).")
        .def_property_readonly("axes", &PidForceDriver::axes)
        .def("start", &PidForceDriver::start)
        .def("stop", &PidForceDriver::stop, py::call_guard<py::gil_scoped_release>())
        .def("set_force", [](PidForceDriver& d, const Vec3& f) { d.setForce(f); }, py::arg("force"))
        .def_property_readonly("writes", &PidForceDriver::writes);

    py::class_<SpaceMouseDevice, Device, std::shared_ptr<SpaceMouseDevice>>(m, "SpaceMouseDevice",
        "A SpaceMouse (input only) from a hidraw path or a hid-recorder fixture file.")
        .def(py::init([](std::optional<std::string> path, std::optional<std::string> recording, bool paced,
                         const std::string& mode, double translationScale, double rotationScale, double deadZone,
                         double fullScale, const Vec3& origin) {
                 if (bool(path) == bool(recording)) throw std::invalid_argument("path/recording: give exactly one");
                 if (mode != "rate" && mode != "position") throw std::invalid_argument("mode: 'rate' or 'position'");
                 SpaceMouseSettings s;
                 s.mode = mode == "rate" ? SpaceMouseSettings::Mode::Rate : SpaceMouseSettings::Mode::Position;
                 s.translationScale = translationScale;
                 s.rotationScale = rotationScale;
                 s.deadZone = deadZone;
                 s.fullScale = fullScale;
                 s.origin = origin;
                 std::unique_ptr<HidTransport> t;
                 if (path) t = openHid(*path);
                 else t = std::make_unique<RecordedTransport>(loadRecording(*recording), paced);
                 return std::make_shared<SpaceMouseDevice>(std::move(t), s);
             }), py::arg("path") = py::none(), py::arg("recording") = py::none(), py::arg("paced") = true,
             py::arg("mode") = "rate", py::arg("translation_scale") = 100.0, py::arg("rotation_scale") = 1.5,
             py::arg("dead_zone") = 0.05, py::arg("full_scale") = 350.0, py::arg("origin") = Vec3(0, 0, 0))
        .def("start", &SpaceMouseDevice::start)
        .def("stop", &SpaceMouseDevice::stop, py::call_guard<py::gil_scoped_release>())
        .def_property_readonly("state", [](SpaceMouseDevice& d) { return stateDict(d.state()); })
        .def_property_readonly("lost", &SpaceMouseDevice::lost);

    py::class_<ForceFeedbackDevice, Device, std::shared_ptr<ForceFeedbackDevice>>(m, "ForceFeedbackDevice",
        "Cursor from one device, force to a HID PID driver.")
        .def(py::init<std::shared_ptr<Device>, std::shared_ptr<PidForceDriver>, double, double>(), py::arg("input"),
             py::arg("output"), py::arg("max_force"), py::arg("max_stiffness"));
}

}  // namespace hs
