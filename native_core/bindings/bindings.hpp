// One function per part of the Python module _core (module.cpp calls them in dependency order).
#pragma once
#include <pybind11/pybind11.h>

namespace hs {
void bindNames(pybind11::module_& m);           ///< bind_names.cpp: the names of the core's choices
void bindSurface(pybind11::module_& m);         ///< bind_surface.cpp: BSplineSurface
void bindMaterial(pybind11::module_& m);        ///< bind_material.cpp: MaterialMap
void bindTools(pybind11::module_& m);           ///< bind_tools.cpp: Tool and the four tools
void bindDynamicSurface(pybind11::module_& m);  ///< bind_dynamic_surface.cpp: DynamicSurface, StepReport
void bindRuntime(pybind11::module_& m);         ///< bind_runtime.cpp: Device, replays, HapticRuntime
void bindDevices(pybind11::module_& m);         ///< bind_devices.cpp: HID, SpaceMouse, force feedback
void bindForceDevices(pybind11::module_& m);    ///< bind_force_devices.cpp: Falcon, OpenHaptics, DHD
}  // namespace hs
