// The Python module _core. Buffers are numpy views (no copies) whose base keeps the owner alive;
// views of the state are read-only so nothing unchecked enters it. Range checks are the core's
// (they throw std::invalid_argument, which pybind11 turns into ValueError); the bindings convert.
#include "bindings.hpp"

PYBIND11_MODULE(_core, m) {
    m.doc() = "HapticSculpt dynamics core: dynamic B-spline surfaces (Dachille et al.), tools, constraints, integrators.";
    hs::bindNames(m);
    hs::bindSurface(m);
    hs::bindMaterial(m);
    hs::bindTools(m);
    hs::bindDynamicSurface(m);
    hs::bindRuntime(m);
    hs::bindDevices(m);  // SpaceMouse, HID PID: subclasses of Device
}
