// The Python module: HapticSculpt._core in an in-tree build, hapticsculpt_core in a wheel (the name
// comes from CMake as HS_MODULE_NAME). Buffers are numpy views (no copies) whose base keeps the owner alive;
// views of the state are read-only so nothing unchecked enters it. Range checks are the core's
// (they throw std::invalid_argument, which pybind11 turns into ValueError); the bindings convert.
#include "bindings.hpp"

PYBIND11_MODULE(HS_MODULE_NAME, m) {
    m.doc() = "HapticSculpt dynamics core: dynamic B-spline surfaces (Dachille et al.), tools, constraints, integrators.";
    m.attr("__version__") = HS_VERSION;
    hs::bindNames(m);
    hs::bindSurface(m);
    hs::bindMaterial(m);
    hs::bindTools(m);
    hs::bindDynamicSurface(m);
    hs::bindRuntime(m);
    hs::bindDevices(m);  // SpaceMouse, HID PID: subclasses of Device
    hs::bindForceDevices(m);
}
