// The names the core's choices have outside it (Python, documents, messages): one table each, so
// parsing, printing, listing and the Python module's tuples all come from the same place.
#pragma once
#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>

#include "constraints.hpp"
#include "dynamic_surface.hpp"
#include "falloff.hpp"
#include "haptic_runtime.hpp"
#include "response_law.hpp"

namespace hs {

template <class E>
struct Named {
    const char* name;
    E value;
};

inline constexpr std::array<Named<IntegratorKind>, 3> kIntegratorNames{{
    {"explicit", IntegratorKind::Explicit}, {"implicit", IntegratorKind::ImplicitCG},
    {"local_global", IntegratorKind::LocalGlobal}}};
inline constexpr std::array<Named<ConstraintKind>, 4> kConstraintNames{{
    {"point", ConstraintKind::Point}, {"tangent", ConstraintKind::Tangent}, {"normal", ConstraintKind::Normal},
    {"curvature", ConstraintKind::Curvature}}};
inline constexpr std::array<Named<Falloff>, 4> kFalloffNames{{
    {"constant", Falloff::Constant}, {"spherical", Falloff::Spherical}, {"cylindrical", Falloff::Cylindrical},
    {"conical", Falloff::Conical}}};
inline constexpr std::array<Named<LawKind>, 3> kLawNames{{
    {"linear", LawKind::Linear}, {"cubic", LawKind::CubicHardening}, {"saturating", LawKind::Saturating}}};
inline constexpr std::array<Named<AirbrushSettings::Map>, 4> kMapNames{{
    {"mass", AirbrushSettings::Map::Mass}, {"damping", AirbrushSettings::Map::Damping},
    {"stiffness", AirbrushSettings::Map::Stiffness}, {"bending", AirbrushSettings::Map::Bending}}};
/// The tools makeTool() builds (tools.cpp).
inline constexpr std::array<const char*, 4> kToolNames{{"rope", "magnet", "orientation", "smooth"}};

/// "a, b, c" for messages.
template <class T, std::size_t N>
std::string listNames(const std::array<T, N>& table) {
    std::string out;
    for (const auto& entry : table) {
        if (!out.empty()) out += ", ";
        if constexpr (std::is_same_v<T, const char*>) out += entry;
        else out += entry.name;
    }
    return out;
}

/// The value named `name`; throws std::invalid_argument("<what>: unknown '<name>' (<names>)").
template <class E, std::size_t N>
E fromName(const std::array<Named<E>, N>& table, const std::string& name, const char* what) {
    for (const auto& entry : table)
        if (name == entry.name) return entry.value;
    throw std::invalid_argument(std::string(what) + ": unknown '" + name + "' (" + listNames(table) + ")");
}

/// The name of `value` ("" if the table does not have it).
template <class E, std::size_t N>
const char* nameOf(const std::array<Named<E>, N>& table, E value) {
    for (const auto& entry : table)
        if (entry.value == value) return entry.name;
    return "";
}

}  // namespace hs
