// Names the core's choices have outside it (Python, documents, messages): each enum's table sits
// beside the enum (Falloff's in falloff.hpp, ...); parsing, printing and listing all read it.
#pragma once
#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace hs {

template <class E>
struct Named {
    const char* name;
    E value;
};

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
