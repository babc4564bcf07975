// One function per layer of the core (native_core/src/<layer>), called by module.cpp bottom up.
#pragma once
#include <pybind11/pybind11.h>

namespace hs {
void bindGeometry(pybind11::module_& m);             ///< geometry.cpp: BSplineSurface, MAX_DEGREE, FALLOFFS
void bindDynamics(pybind11::module_& m);             ///< dynamics.cpp: MaterialMap, LAWS
void bindToolsAndConstraints(pybind11::module_& m);  ///< tools_and_constraints.cpp: Tool, TOOLS, TOOL_INFO, CONSTRAINTS
void bindSolvers(pybind11::module_& m);              ///< solvers.cpp: DynamicSurface, StepReport, INTEGRATORS
void bindDevices(pybind11::module_& m);              ///< devices.cpp: Device, the replay and external devices
void bindHidDevices(pybind11::module_& m);           ///< hid_devices.cpp: HID, SpaceMouse, HID PID force feedback
void bindForceDevices(pybind11::module_& m);         ///< force_devices.cpp: Falcon, Haply, OpenHaptics, DHD, limits
void bindRuntime(pybind11::module_& m);              ///< runtime.cpp: HapticRuntime, DEFAULTS, MAPS
}  // namespace hs
