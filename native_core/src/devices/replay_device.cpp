#include "devices/replay_device.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hs {

ReplayDevice::ReplayDevice(std::vector<double> t, Points xyz, Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> quat,
                           std::vector<std::uint32_t> buttons)
    : t_(std::move(t)), xyz_(std::move(xyz)), q_(std::move(quat)), buttons_(std::move(buttons)) {
    const auto n = static_cast<Eigen::Index>(t_.size());
    if (n == 0) throw std::invalid_argument("t: expected at least one sample");
    if (xyz_.rows() != n || q_.rows() != n || static_cast<Eigen::Index>(buttons_.size()) != n)
        throw std::invalid_argument("xyz/quat/buttons: expected one row per timestamp");
    for (size_t i = 0; i < t_.size(); ++i) {
        if (!std::isfinite(t_[i]) || (i > 0 && !(t_[i] > t_[i - 1])))
            throw std::invalid_argument("t: timestamps must be finite and strictly increasing");
    }
    if (!xyz_.allFinite() || !q_.allFinite()) throw std::invalid_argument("xyz/quat: must be finite");
}

bool ReplayDevice::sample(double t, DeviceSample& out) {
    const size_t n = t_.size();
    size_t k = 0;
    double a = 0;
    if (n > 1 && t > t_[0]) {
        if (t >= t_[n - 1]) {
            k = n - 1;
        } else {
            if (hint_ >= n - 1 || t_[hint_] > t) hint_ = 0;
            while (hint_ + 1 < n && t_[hint_ + 1] <= t) ++hint_;
            k = hint_;
            a = (t - t_[k]) / (t_[k + 1] - t_[k]);
        }
    }
    const auto kk = static_cast<Eigen::Index>(k);
    if (a == 0.0) {
        out.position = xyz_.row(kk).transpose();
        out.orientation = Eigen::Quaterniond(q_(kk, 0), q_(kk, 1), q_(kk, 2), q_(kk, 3));
    } else {
        out.position = (xyz_.row(kk) + a * (xyz_.row(kk + 1) - xyz_.row(kk))).transpose();
        Eigen::Matrix<double, 1, 4> q0 = q_.row(kk), q1 = q_.row(kk + 1);
        if (q0.dot(q1) < 0) q1 = -q1;
        Eigen::Matrix<double, 1, 4> q = q0 + a * (q1 - q0);
        q /= q.norm();
        out.orientation = Eigen::Quaterniond(q(0), q(1), q(2), q(3));
    }
    out.buttons = buttons_[k];
    out.valid = true;
    return true;
}

}  // namespace hs
