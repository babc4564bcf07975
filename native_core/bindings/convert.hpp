// Conversions the bindings share: numpy views of core buffers and checked arrays into the core.
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <vector>

#include "types.hpp"

namespace hs {

using DoubleArray = pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>;

/// A read-only numpy view of `data` (C order) whose base `owner` keeps the memory alive.
pybind11::array view(const double* data, std::vector<pybind11::ssize_t> shape, pybind11::handle owner);
/// `rows` points from an array whose last axis has 3 coordinates (the core checks their range).
Points pointsFrom(const DoubleArray& a, Eigen::Index rows, const char* name);
/// Three numbers as a point (the core checks their range).
Vec3 vec3(const std::vector<double>& v, const char* name);

}  // namespace hs
