// A Novint Falcon on its standard firmware, emulated behind the Transport for the tests: it reads
// command frames, homes after a while in homing mode, moves its tip as a mass with damping under
// the motors' force (the torques the commands stand for, by virtual work) and a hand that holds
// the grip through a spring, and answers each command with a status frame (encoder counts from
// the tip's motor angles, homing bits, the grip's buttons). Faults on request: noise and cut
// frames in the stream, reads that return a few bytes at a time, a link that dies.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>

#include "devices/falcon/falcon_frames.hpp"
#include "devices/falcon/falcon_kinematics.hpp"
#include "devices/falcon/falcon_transport.hpp"

namespace hs::falcon {

class Emulator final : public Transport {
public:
    double mass = 0.15;           ///< kg at the tip
    double damping = 2.0;         ///< N s/m: the mechanism's own
    double handStiffness = 300;   ///< N/m: the hand holding the grip
    double handDamping = 4;       ///< N s/m
    double dt = 0.001;            ///< s of device time per command frame (the firmware's cycle)
    double countsPerNewtonMetre = 1e4;
    int homingFrames = 40;        ///< frames in homing mode before each encoder reports homed
    int noiseEvery = 0;           ///< > 0: every n-th answer comes after noise and a cut frame
    std::size_t readChunk = 64;   ///< the most bytes one read returns
    long loseAfter = -1;          ///< >= 0: the link dies after this many command frames
    std::function<Vec3d(double)> hand = [](double) { return Vec3d(0, 0, 0.11); };
    std::function<std::uint8_t(double)> buttons = [](double) { return std::uint8_t{0}; };

    // what the test looks at
    Vec3d tip = Vec3d(0, 0, 0.11), velocity = Vec3d::Zero();
    double time = 0;
    long commands = 0, malformed = 0;
    double largestForce = 0;      ///< N: the largest motor force seen
    Vec3d lastForce = Vec3d::Zero();
    Command last;

    bool write(const std::uint8_t* data, std::size_t n) override {
        if (dead()) return false;
        for (std::size_t at = 0; at + kFrameSize <= n; at += kFrameSize) {
            Command c;
            if (!decodeCommand(data + at, c)) {
                ++malformed;
                continue;
            }
            step(c);
        }
        return true;
    }

    long read(std::uint8_t* data, std::size_t capacity, double) override {
        if (dead()) return -1;
        const std::size_t n = std::min({capacity, readChunk, outLen_});
        std::memcpy(data, out_.data(), n);
        std::memmove(out_.data(), out_.data() + n, outLen_ - n);
        outLen_ -= n;
        return static_cast<long>(n);
    }

private:
    bool dead() const { return loseAfter >= 0 && commands >= loseAfter; }

    void step(const Command& c) {
        ++commands;
        last = c;
        if (c.homing && homed_ < 7 && ++homingCount_ >= homingFrames) {
            homed_ = static_cast<std::uint8_t>((homed_ << 1) | 1);  // one encoder after another
            homingCount_ = 0;
        }
        ArmAngles a;
        const bool reach = inverseKinematics(tip, a);
        Vec3d force = Vec3d::Zero();
        if (reach) {
            Vec3d torques;
            for (int i = 0; i < 3; ++i) torques[i] = -c.motor[static_cast<std::size_t>(i)] / countsPerNewtonMetre;
            force = jacobian(a).transpose() * torques;  // virtual work: f = J^T tau
        }
        lastForce = force;
        largestForce = std::max(largestForce, force.norm());
        const Vec3d handForce = handStiffness * (hand(time) - tip) - handDamping * velocity;
        velocity += dt * (force + handForce - damping * velocity) / mass;
        tip += dt * velocity;
        time += dt;
        Status s;
        if (inverseKinematics(tip, a))
            for (int i = 0; i < 3; ++i) s.encoder[static_cast<std::size_t>(i)] = static_cast<std::int16_t>(std::lround(countOfAngle(a.motor[i])));
        s.homed = homed_;
        s.buttons = homed_ == 7 ? buttons(time) : 0;
        const Frame f = encodeStatus(s);
        if (noiseEvery > 0 && commands % noiseEvery == 0) {
            push(reinterpret_cast<const std::uint8_t*>("\x01<AB>"), 5);
            push(f.data(), 9);  // a frame cut short
        }
        push(f.data(), f.size());
    }

    void push(const std::uint8_t* data, std::size_t n) {
        n = std::min(n, out_.size() - outLen_);  // (a full queue drops, as a USB FIFO does)
        std::memcpy(out_.data() + outLen_, data, n);
        outLen_ += n;
    }

    std::array<std::uint8_t, 4096> out_{};
    std::size_t outLen_ = 0;
    int homingCount_ = 0;
    std::uint8_t homed_ = 0;
};

}  // namespace hs::falcon
