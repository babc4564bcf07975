// Python binding of the haptic runtime and the devices (runtime_bindings.cpp).
#pragma once
#include <pybind11/pybind11.h>

namespace hs {
void bindRuntime(pybind11::module_& m);
}
