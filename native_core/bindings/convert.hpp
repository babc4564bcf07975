// Conversions the bindings share: numpy views of core buffers and checked arrays into the core.
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <vector>

#include "common/names.hpp"
#include "common/types.hpp"

namespace hs {

/// The names in a Named table (common/names.hpp) as a tuple: INTEGRATORS, FALLOFFS and the like.
template <class E, std::size_t N>
pybind11::tuple namesOf(const std::array<Named<E>, N>& table) {
    pybind11::tuple out(N);
    for (std::size_t i = 0; i < N; ++i) out[i] = table[i].name;
    return out;
}


using DoubleArray = pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>;

/// A read-only numpy view of `data` (C order) whose base `owner` keeps the memory alive.
pybind11::array view(const double* data, std::vector<pybind11::ssize_t> shape, pybind11::handle owner);
/// `rows` points from an array whose last axis has 3 coordinates (the core checks their range).
Points pointsFrom(const DoubleArray& a, Eigen::Index rows, const char* name);
/// Three numbers as a point (the core checks their range).
Vec3 vec3(const std::vector<double>& v, const char* name);

}  // namespace hs
