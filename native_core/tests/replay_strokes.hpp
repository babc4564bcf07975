// Strokes the replay tests play: a hand at 1 kHz whose position is `at(t)`, holding the grab
// button from 50 ms until `release` s, as a ReplayDevice.
#pragma once
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "devices/replay_device.hpp"

template <class Position>
std::shared_ptr<hs::ReplayDevice> replayStroke(double seconds, double release, Position at) {
    const int n = static_cast<int>(seconds * 1000) + 1;
    std::vector<double> t(static_cast<size_t>(n));
    hs::Points xyz(n, 3);
    Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> q(n, 4);
    std::vector<std::uint32_t> buttons(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
        const double ti = i * 1e-3;
        t[static_cast<size_t>(i)] = ti;
        xyz.row(i) = at(ti).transpose();
        q.row(i) << 1, 0, 0, 0;
        buttons[static_cast<size_t>(i)] = ti >= 0.05 && ti < release ? 1 : 0;
    }
    return std::make_shared<hs::ReplayDevice>(t, xyz, q, buttons);
}

// bench/haptic_force.py's rope stroke: the cursor rests on the patch, grabs, pulls up and around.
inline hs::Vec3 pulledUpAndAround(double t) {
    const double tau = t > 0.1 ? t - 0.1 : 0.0;
    return {12.3 + 8 * std::sin(1.3 * tau), -7.1 + 6 * std::sin(0.9 * tau), 14 * std::pow(std::sin(1.2 * tau), 2) + 4 * tau};
}
