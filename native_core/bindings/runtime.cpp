// The threaded runtime (HapticRuntime): a session over a surface and a device.
// The loops never take the GIL; calls that wait (stop) release it.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstdio>
#include <optional>

#include "bindings.hpp"
#include "convert.hpp"
#include "runtime/haptic_runtime.hpp"
#include "runtime/multirate_replay.hpp"
#include "common/names.hpp"

namespace py = pybind11;

namespace hs {
namespace {

AirbrushSettings airbrushSettings(const py::object& map, double radius, double factor, double strength, double rate) {
    AirbrushSettings a;
    if (!map.is_none()) {
        if (!py::isinstance<py::str>(map)) throw std::invalid_argument("map: one of 'mass', 'damping', 'stiffness', or None (off)");
        const std::string name = py::cast<std::string>(map);
        for (const auto& entry : kMapNames)
            if (name == entry.name) a.map = entry.value;
        if (a.map == AirbrushSettings::Map::Off)
            throw std::invalid_argument("map: one of 'mass', 'damping', 'stiffness', or None (off)");
    }
    a.radius = radius;
    a.factor = factor;
    a.strength = strength;
    a.rate = rate;
    a.validate();
    return a;
}

}  // namespace

void bindRuntime(py::module_& m) {
    const RuntimeSettings kDefaults;  // the arguments' defaults are the settings' own
    py::dict defaults;
    defaults["haptic_rate"] = kDefaults.hapticRate;
    defaults["sim_dt"] = kDefaults.simDt;
    defaults["realtime"] = kDefaults.realtime;
    m.attr("DEFAULTS") = defaults;
    m.attr("MAPS") = namesOf(kMapNames);
    m.def("replay_multirate", [](DynamicSurface& surface, std::shared_ptr<Device> device, double seconds, double hapticRate,
                                 double simDt, double stepCost, double maxLag, bool catchUp, double latency) {
        if (!device) throw std::invalid_argument("device: required");
        MultirateSettings s;
        s.hapticRate = hapticRate;
        s.simDt = simDt;
        s.stepCost = stepCost;
        s.maxLag = maxLag;
        s.catchUp = catchUp;
        s.latency = latency;
        MultirateTicks r;
        {
            py::gil_scoped_release release;
            r = replayMultirate(surface, *device, seconds, s);
        }
        py::dict d;
        d["t"] = py::array_t<double>(static_cast<py::ssize_t>(r.t.size()), r.t.data());
        d["state_time"] = py::array_t<double>(static_cast<py::ssize_t>(r.stateTime.size()), r.stateTime.data());
        d["position"] = Eigen::MatrixXd(r.cursor);
        d["estimated_force"] = Eigen::MatrixXd(r.force);
        d["dropped_sim_time"] = r.droppedSimTime;
        d["steps"] = r.steps;
        d["doubled_steps"] = r.doubledSteps;
        return d;
    }, py::arg("surface"), py::arg("device"), py::arg("seconds"), py::arg("haptic_rate") = 1000.0, py::arg("sim_dt") = 1e-3,
       py::arg("step_cost") = 0.0, py::arg("max_lag") = 0.01, py::arg("catch_up") = true, py::arg("latency") = 0.0,
       "A session's two rates on a virtual clock (runtime/multirate_replay.hpp): the simulation's steps each cost "
       "step_cost s, the haptic loop renders at haptic_rate from the newest state that reached it by then (latency s after "
       "its step ended). Steps `surface` "
       "in place. Returns the ticks (t, state_time, position, estimated_force) and dropped_sim_time, steps, "
       "doubled_steps. step_cost=0 gives the force of a simulation at the haptic rate.");
    py::class_<HapticRuntime, std::shared_ptr<HapticRuntime>>(m, "HapticRuntime",
        "The simulation and haptic threads of one session over a surface and a device.")
        .def(py::init([](std::shared_ptr<DynamicSurface> surface, std::shared_ptr<Device> device, double hapticRate,
                         double simDt, double graphicsRate, double maxForce, double maxStiffness, double staleLimit,
                         double fadeTime, double maxLag, double logSeconds, bool stopWhenFinished, bool realtime,
                         double idleRate, double spin, int simNice, bool catchUp) {
                 RuntimeSettings s;
                 s.hapticRate = hapticRate;
                 s.simDt = simDt;
                 s.graphicsRate = graphicsRate;
                 s.maxForce = maxForce;
                 s.maxStiffness = maxStiffness;
                 s.staleLimit = staleLimit;
                 s.fadeTime = fadeTime;
                 s.maxLag = maxLag;
                 s.logSeconds = logSeconds;
                 s.stopWhenFinished = stopWhenFinished;
                 s.realtime = realtime;
                 s.idleRate = idleRate;
                 s.spin = spin;
                 s.simNice = simNice;
                 s.catchUp = catchUp;
                 return std::make_shared<HapticRuntime>(std::move(surface), std::move(device), s);
             }), py::arg("surface"), py::arg("device"), py::arg("haptic_rate") = kDefaults.hapticRate, py::arg("sim_dt") = kDefaults.simDt,
             py::arg("graphics_rate") = kDefaults.graphicsRate, py::arg("max_force") = kDefaults.maxForce, py::arg("max_stiffness") = kDefaults.maxStiffness,
             py::arg("stale_limit") = kDefaults.staleLimit, py::arg("fade_time") = kDefaults.fadeTime, py::arg("max_lag") = kDefaults.maxLag,
             py::arg("log_seconds") = kDefaults.logSeconds, py::arg("stop_when_finished") = kDefaults.stopWhenFinished, py::arg("realtime") = kDefaults.realtime,
             py::arg("idle_rate") = kDefaults.idleRate, py::arg("spin") = kDefaults.spin, py::arg("sim_nice") = kDefaults.simNice, py::arg("catch_up") = kDefaults.catchUp)
        .def("start", &HapticRuntime::start, py::call_guard<py::gil_scoped_release>(),
             "Start the device and both threads (GIL released: a device may take a while, e.g. a Falcon homing "
             "or a service answering from a Python thread).")
        .def("stop", &HapticRuntime::stop, py::call_guard<py::gil_scoped_release>(),
             "Zero the force, join both threads (GIL released while waiting).")
        .def_property_readonly("running", &HapticRuntime::running)
        .def("status", [](const HapticRuntime& r) {
            const RuntimeStatus s = r.status();
            py::dict d;
            d["running"] = s.running;
            d["elapsed"] = s.elapsed;
            d["haptic_hz"] = s.hapticHz;
            d["sim_hz"] = s.simHz;
            d["haptic_period_p50_ms"] = s.periodP50 * 1e3;
            d["haptic_period_p99_ms"] = s.periodP99 * 1e3;
            d["haptic_period_max_ms"] = s.periodMax * 1e3;
            d["latency_p50_ms"] = s.latencyP50 * 1e3;
            d["latency_p99_ms"] = s.latencyP99 * 1e3;
            d["haptic_ticks"] = s.hapticTicks;
            d["sim_steps"] = s.simSteps;
            d["refused_steps"] = s.refusedSteps;
            d["strokes"] = s.strokes;
            d["dropped_sim_time"] = s.droppedSimTime;
            d["doubled_steps"] = s.doubledSteps;
            d["force"] = Vec3(s.force);
            d["estimate_age_ms"] = s.estimateAge * 1e3;
            d["realtime_priority"] = s.realtimePriority;
            d["realtime_how"] = r.realtimeHow();
            d["error"] = s.error;
            d["cursor"] = Vec3(s.cursor);
            d["orientation"] = std::vector<double>{s.orientation.w(), s.orientation.x(), s.orientation.y(), s.orientation.z()};
            d["grab"] = s.grab;
            d["contact"] = s.contactValid ? py::cast(Vec3(s.contact)) : py::object(py::none());
            d["spraying"] = s.spraying;
            return d;
        })
        .def("take_poles", [](HapticRuntime& r) -> py::object {
            Points p;
            if (!r.takePoles(p)) return py::none();
            return py::cast(p);
        }, "Newest pole snapshot ((nu*nv, 3) array) if one arrived since the last call, else None.")
        .def("take_painted_map", [](HapticRuntime& r) -> py::object {
            PaintedMap p;
            if (!r.takePaintedMap(p)) return py::none();
            py::dict d;
            d["map"] = mapName(p.map);
            py::array_t<double> values({p.rows, p.cols});
            std::copy(p.values.data(), p.values.data() + p.values.size(), values.mutable_data());
            d["values"] = values;
            return d;
        }, "The map a spray is painting ({'map': name, 'values': (rows, cols) array}) if it changed since the last "
           "call, else None; published at the graphics rate while the spray goes on.")
        .def("take_stroke", [](HapticRuntime& r) -> py::object {
            StrokeSnapshot s;
            if (!r.takeStroke(s)) return py::none();
            py::dict d;
            d["time"] = s.time;
            d["step"] = s.step;
            d["poles"] = py::cast(s.poles);
            d["velocities"] = py::cast(s.velocities);
            d["rest_lengths"] = py::cast(s.restLengths);
            d["bending_reference"] = py::cast(Eigen::MatrixXd(s.bendingReference));
            d["painted"] = s.painted == AirbrushSettings::Map::Off ? py::object(py::none()) : py::str(mapName(s.painted));
            d["edit"] = s.edit == 0 ? py::object(py::none()) : py::int_(s.edit);
            py::dict maps;
            for (size_t k = 0; k < kMaps.size(); ++k) {
                if (s.edit == 0 && kMaps[k] != s.painted) continue;
                py::array_t<double> values({s.maps[k].rows, s.maps[k].cols});
                std::copy(s.maps[k].values.data(), s.maps[k].values.data() + s.maps[k].values.size(), values.mutable_data());
                maps[mapName(kMaps[k])] = values;
            }
            d["maps"] = maps;
            return d;
        }, "The oldest uncollected event, else None: a stroke's end, a spray's end or an applied edit, each with its "
           "simulation time and step count and the poles, velocities and rest lengths it left. 'painted' names a spray's map, 'edit' an edit's id; 'maps' "
           "holds the maps it carries ((rows, cols) arrays by name: the painted one, or all three after an edit).")
        .def("post_edit", [](HapticRuntime& r, std::uint64_t id, std::shared_ptr<DynamicSurface> next, bool restore,
                             bool keepMaps, bool keepShape) {
            SurfaceEdit e;
            e.id = id;
            e.next = std::move(next);
            e.restore = restore;
            e.keepMaps = keepMaps;
            e.keepShape = keepShape;
            py::gil_scoped_release release;  // preparing `next` factors its system
            return r.postEdit(std::move(e));
        }, py::arg("id"), py::arg("next") = nullptr, py::arg("restore") = false, py::arg("keep_maps") = true,
           py::arg("keep_shape") = false,
           "Queues an edit for the simulation thread to take up between two steps: `next` (a configured surface of the "
           "same sampling; None: none) continues from the live surface's motion, or with restore=True replaces it as "
           "it is; keep_maps carries the live maps over; keep_shape then makes the current shape the rest shape. Its "
           "event (take_stroke, 'edit' = id) follows. Returns the simulation steps taken when it was queued.")
        .def_property_readonly("surface", [](const HapticRuntime& r) {
            if (!r.joined()) throw std::runtime_error("session: the simulation owns its surface until stop()");
            return r.surface();
        }, "The surface the simulation stepped last (edits replace it); readable once stopped.")
        .def("set_airbrush", [](HapticRuntime& r, py::object map, double radius, double factor, double strength, double rate) {
            r.setAirbrush(airbrushSettings(map, radius, factor, strength, rate));
        }, py::arg("map"), py::arg("radius") = 0.08, py::arg("factor") = 3.0, py::arg("strength") = 0.25, py::arg("rate") = 30.0,
           "Airbrush during the session: while `map` is set, the device's first button sprays it (the tool lets go) with a "
           "dab every 1/rate s at the mass point nearest the cursor, moving it toward factor x its mean at the spray's "
           "start; each spray ends as one stroke. None switches it off.")
        .def_static("validate_airbrush", [](py::object map, double radius, double factor, double strength, double rate) {
            airbrushSettings(map, radius, factor, strength, rate);
        }, py::arg("map"), py::arg("radius") = 0.08, py::arg("factor") = 3.0, py::arg("strength") = 0.25, py::arg("rate") = 30.0,
           "Raises ValueError naming the first bad argument of set_airbrush.")
        .def("ticks", [](const HapticRuntime& r) {
            const auto& ticks = r.ticks();
            const auto n = static_cast<py::ssize_t>(ticks.size());
            py::array_t<double> t(n), state(n), cursor({n, py::ssize_t(3)}), est({n, py::ssize_t(3)}), ren({n, py::ssize_t(3)});
            py::array_t<std::uint32_t> buttons(n);
            for (py::ssize_t i = 0; i < n; ++i) {
                const HapticTick& k = ticks[static_cast<size_t>(i)];
                t.mutable_at(i) = k.t;
                state.mutable_at(i) = k.stateTime;
                buttons.mutable_at(i) = k.cursor.buttons;
                for (py::ssize_t c = 0; c < 3; ++c) {
                    cursor.mutable_at(i, c) = k.cursor.position[c];
                    est.mutable_at(i, c) = k.estimated[c];
                    ren.mutable_at(i, c) = k.rendered[c];
                }
            }
            py::array_t<double> quat({n, py::ssize_t(4)});
            for (py::ssize_t i = 0; i < n; ++i) {
                const auto& q = ticks[static_cast<size_t>(i)].cursor.orientation;
                quat.mutable_at(i, 0) = q.w(); quat.mutable_at(i, 1) = q.x(); quat.mutable_at(i, 2) = q.y(); quat.mutable_at(i, 3) = q.z();
            }
            py::dict d;
            d["t"] = t; d["position"] = cursor; d["orientation"] = quat; d["buttons"] = buttons;
            d["estimated_force"] = est; d["rendered_force"] = ren; d["state_time"] = state;
            return d;
        }, "Logged haptic ticks (after stop, with log_seconds > 0): t, cursor, buttons, estimated and rendered force, "
           "and the simulated time of the state the estimate came from.")
        .def("force_errors", [](const HapticRuntime& r, double floor) {
            std::vector<double> e;
            {
                py::gil_scoped_release release;
                e = r.forceErrors(floor);
            }
            return e;
        }, py::arg("floor") = 0.05,
           "Per logged tick: |estimated - exact| / max(|exact|, floor * max|exact|), exact from the surface the "
           "simulation computed around that time.");
}

}  // namespace hs
