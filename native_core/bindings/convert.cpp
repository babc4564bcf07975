#include "convert.hpp"

#include <stdexcept>
#include <string>

namespace py = pybind11;

namespace hs {

py::array view(const double* data, std::vector<py::ssize_t> shape, py::handle owner) {
    std::vector<py::ssize_t> strides(shape.size());
    py::ssize_t s = sizeof(double);
    for (size_t i = shape.size(); i-- > 0;) { strides[i] = s; s *= shape[i]; }
    py::array a(py::dtype::of<double>(), shape, strides, data, owner);
    a.attr("setflags")(py::arg("write") = false);
    return a;
}

Points pointsFrom(const DoubleArray& a, Eigen::Index rows, const char* name) {
    if (a.ndim() < 2 || a.shape(a.ndim() - 1) != 3 || a.size() != rows * 3)
        throw std::invalid_argument(std::string(name) + ": expected " + std::to_string(rows) + " points of 3 coordinates");
    Points p(rows, 3);
    std::copy(a.data(), a.data() + rows * 3, p.data());
    return p;
}

Vec3 vec3(const std::vector<double>& v, const char* name) {
    if (v.size() != 3) throw std::invalid_argument(std::string(name) + ": expected 3 numbers");
    return requirePoint(Vec3(v[0], v[1], v[2]), name);
}

}  // namespace hs
