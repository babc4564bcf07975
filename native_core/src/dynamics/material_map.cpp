#include "dynamics/material_map.hpp"

#include "geometry/bspline_surface.hpp"  // kMaxMaterial

#include <cmath>
#include <stdexcept>
#include <string>

namespace hs {

MaterialMap::MaterialMap(double value, const char* name)
    : name_(name), values_(std::make_shared<Eigen::VectorXd>(Eigen::VectorXd::Constant(1, value))) {
    checkValue(value, "value");
}

void MaterialMap::checkValue(double value, const char* what) const {
    if (!std::isfinite(value) || value > kMaxMaterial || (value < kMinMaterial && !(value == 0 && allowZero_)))
        throw std::invalid_argument(std::string(name_) + " " + what + ": must be " + (allowZero_ ? "0 or " : "") +
                                    "in [1e-12, 1e12], got " + std::to_string(value));
}

double MaterialMap::at(double u, double v) const {
    if (uniform()) return (*values_)[0];
    const double x = std::clamp(u, 0.0, 1.0) * (rows_ - 1), y = std::clamp(v, 0.0, 1.0) * (cols_ - 1);
    const int r = std::min(static_cast<int>(x), rows_ - 2), c = std::min(static_cast<int>(y), cols_ - 2);
    const double fx = x - r, fy = y - c;
    const double* p = values_->data();
    return (1 - fx) * ((1 - fy) * p[r * cols_ + c] + fy * p[r * cols_ + c + 1]) +
           fx * ((1 - fy) * p[(r + 1) * cols_ + c] + fy * p[(r + 1) * cols_ + c + 1]);
}

void MaterialMap::setUniform(double value) {
    checkValue(value, "value");
    rows_ = cols_ = 1;
    values_ = std::make_shared<Eigen::VectorXd>(Eigen::VectorXd::Constant(1, value));
    ++version_;
}

void MaterialMap::setValues(int rows, int cols, const Eigen::VectorXd& values) {
    if (rows < 1 || cols < 1 || (rows == 1) != (cols == 1))
        throw std::invalid_argument(std::string(name_) + " shape: need rows, cols >= 2 (or 1x1 for uniform)");
    if (values.size() != static_cast<Eigen::Index>(rows) * cols)
        throw std::invalid_argument(std::string(name_) + " values: expected rows*cols entries");
    for (Eigen::Index i = 0; i < values.size(); ++i) checkValue(values[i], "values");
    rows_ = rows;
    cols_ = cols;
    values_ = std::make_shared<Eigen::VectorXd>(values);
    ++version_;
}

void MaterialMap::resize(int rows, int cols) {
    if (rows < 2 || cols < 2) throw std::invalid_argument(std::string(name_) + " resolution: must be >= 2x2");
    Eigen::VectorXd nv(static_cast<Eigen::Index>(rows) * cols);
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) nv[r * cols + c] = at(static_cast<double>(r) / (rows - 1), static_cast<double>(c) / (cols - 1));
    rows_ = rows;
    cols_ = cols;
    values_ = std::make_shared<Eigen::VectorXd>(std::move(nv));
    ++version_;
}

void MaterialMap::dab(double u, double v, double radius, double value, Falloff falloff, double strength,
                      int paintResolution) {
    if (!std::isfinite(u) || !std::isfinite(v)) throw std::invalid_argument("uv: must be finite");
    if (!(radius > 0) || !std::isfinite(radius)) throw std::invalid_argument("radius: must be finite and > 0");
    if (!(strength >= 0 && strength <= 1)) throw std::invalid_argument("strength: must be in [0, 1]");
    checkValue(value, "value");
    if (uniform()) resize(paintResolution, paintResolution);
    for (int r = 0; r < rows_; ++r)
        for (int c = 0; c < cols_; ++c) {
            const double du = static_cast<double>(r) / (rows_ - 1) - u, dv = static_cast<double>(c) / (cols_ - 1) - v;
            const double w = strength * falloffWeight(falloff, std::sqrt(du * du + dv * dv) / radius);
            double& x = (*values_)[r * cols_ + c];
            x += w * (value - x);
        }
    ++version_;
}

}  // namespace hs
