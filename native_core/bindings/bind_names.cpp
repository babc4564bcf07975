// The names of the core's choices as tuples (HapticSculpt.core.INTEGRATORS and the like).
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "names.hpp"

namespace py = pybind11;

namespace hs {
namespace {

template <class T, std::size_t N>
py::tuple names(const std::array<T, N>& table) {
    py::tuple out(N);
    for (std::size_t i = 0; i < N; ++i) {
        if constexpr (std::is_same_v<T, const char*>) out[i] = table[i];
        else out[i] = table[i].name;
    }
    return out;
}

}  // namespace

void bindNames(py::module_& m) {
    m.attr("MAX_DEGREE") = kMaxDegree;
    m.attr("INTEGRATORS") = names(kIntegratorNames);
    m.attr("TOOLS") = names(kToolNames);
    m.attr("CONSTRAINTS") = names(kConstraintNames);
    m.attr("FALLOFFS") = names(kFalloffNames);
    m.attr("LAWS") = names(kLawNames);
    m.attr("MAPS") = names(kMapNames);
}

}  // namespace hs
