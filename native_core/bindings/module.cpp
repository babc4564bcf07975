// The Python module: HapticSculpt._core in an in-tree build, hapticsculpt_core in a wheel (the name
// comes from CMake as HS_MODULE_NAME). Buffers are numpy views (no copies) whose base keeps the owner alive;
// views of the state are read-only so nothing unchecked enters it. Range checks are the core's
// (they throw std::invalid_argument, which pybind11 turns into ValueError); the bindings convert.
#include "bindings.hpp"

PYBIND11_MODULE(HS_MODULE_NAME, m) {
    m.doc() = "HapticSculpt dynamics core: dynamic B-spline surfaces (Dachille et al.), tools, constraints, integrators.";
    m.attr("__version__") = HS_VERSION;
    hs::bindGeometry(m);
    hs::bindDynamics(m);
    hs::bindToolsAndConstraints(m);
    hs::bindSolvers(m);
    hs::bindDevices(m);
    hs::bindHidDevices(m);  // SpaceMouse, HID PID: subclasses of Device
    hs::bindForceDevices(m);
    hs::bindRuntime(m);
}
