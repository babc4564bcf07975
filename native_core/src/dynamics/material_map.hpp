// A scalar material quantity (mass, damping or stiffness density) over the unit (u, v) square.
#pragma once
#include <Eigen/Core>
#include <cstdint>
#include <memory>

#include "geometry/falloff.hpp"

namespace hs {

/// Node-centred grid with bilinear lookup; a 1x1 map is uniform and needs no lookup at all.
/// Values are stored row-major with index r * cols + c, r along u.
class MaterialMap {
public:
    MaterialMap(double value, const char* name);

    const char* name() const { return name_; }
    bool uniform() const { return values_->size() == 1; }
    int rows() const { return rows_; }
    int cols() const { return cols_; }
    const Eigen::VectorXd& values() const { return *values_; }
    /// Shared storage, so a numpy view stays valid (if stale) after the map is resized.
    std::shared_ptr<Eigen::VectorXd> storage() const { return values_; }
    /// Increments on every change so owners refresh derived coefficients only when needed.
    std::uint64_t version() const { return version_; }

    double at(double u, double v) const;  ///< bilinear lookup at normalised (u, v) in [0, 1]^2
    double mean() const { return values_->mean(); }

    void setUniform(double value);
    /// Replaces the grid; values must be finite and > 0 (>= 0 if zero is allowed).
    void setValues(int rows, int cols, const Eigen::VectorXd& values);
    /// Resamples the current content onto a rows x cols grid.
    void resize(int rows, int cols);
    /// Airbrush dab: moves nodes within `radius` of (u, v) toward `value` by strength * falloff.
    /// A uniform map is first resampled to `paintResolution` x `paintResolution`.
    void dab(double u, double v, double radius, double value, Falloff falloff, double strength,
             int paintResolution = 64);

    void allowZero(bool allow) { allowZero_ = allow; }

private:
    void checkValue(double value, const char* what) const;
    const char* name_;
    int rows_ = 1, cols_ = 1;
    std::shared_ptr<Eigen::VectorXd> values_;
    std::uint64_t version_ = 0;
    bool allowZero_ = false;
};

}  // namespace hs
