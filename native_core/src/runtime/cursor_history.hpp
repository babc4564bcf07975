// The haptic loop's recent device samples, so the simulation can read the cursor at its own
// simulated time. The simulation runs up to max_lag behind the clock; a step that took the newest
// sample saw the hand up to that lag ahead of the step, so its surface (and the force the haptic
// loop renders from it) was not the one a step at the haptic rate would give. Taken at the step's
// end, the cursor is where the hand was then, whatever the lag.
// One writer (the haptic thread), one reader (the simulation thread); lock-free, allocation-free.
// Each slot is a sequence lock over atomics (release stores, acquire loads: no standalone fences,
// which ThreadSanitizer cannot follow): a slot the writer reuses while it is read is detected and
// read again, never torn.
#pragma once
#include <array>
#include <atomic>
#include <cstdint>

#include "devices/device.hpp"

namespace hs {

class CursorHistory {
public:
    /// 512 samples: half a second at 1 kHz, far beyond any lag the simulation is allowed.
    static constexpr std::uint64_t kSlots = 512;

    /// Writer: the sample the device gave at time t (s, increasing).
    void push(double t, const DeviceSample& s) {
        const std::uint64_t i = head_.load(std::memory_order_relaxed);
        Slot& slot = slots_[i % kSlots];
        const std::uint64_t seq = slot.seq.load(std::memory_order_relaxed);
        slot.seq.store(seq + 1, std::memory_order_relaxed);  // odd: being written
        // (release stores: a reader that sees any of the new values sees the odd count after it)
        slot.v[0].store(t, std::memory_order_release);
        for (int k = 0; k < 3; ++k) slot.v[1 + k].store(s.position[k], std::memory_order_release);
        slot.v[4].store(s.orientation.w(), std::memory_order_release);
        slot.v[5].store(s.orientation.x(), std::memory_order_release);
        slot.v[6].store(s.orientation.y(), std::memory_order_release);
        slot.v[7].store(s.orientation.z(), std::memory_order_release);
        slot.buttons.store(s.buttons, std::memory_order_release);
        slot.seq.store(seq + 2, std::memory_order_release);
        head_.store(i + 1, std::memory_order_release);
    }

    /// Reader: the cursor at time t, interpolated between the samples around it (position
    /// linearly, orientation by slerp; the buttons of the sample at or before t). Before the
    /// oldest sample kept: the oldest; after the newest: the newest. False while there is none.
    bool at(double t, DeviceSample& out) const {
        for (;;) {
            const std::uint64_t head = head_.load(std::memory_order_acquire);
            if (head == 0) return false;
            const std::uint64_t oldest = head > kSlots - 1 ? head - (kSlots - 1) : 0;
            Sample later, earlier;
            std::uint64_t i = head - 1;
            if (!read(i, later)) continue;
            if (later.t <= t) {
                out = later.s;
                return true;
            }
            bool found = false, torn = false;
            while (i > oldest) {
                --i;
                if (!read(i, earlier)) {
                    torn = true;
                    break;
                }
                if (earlier.t <= t) {
                    found = true;
                    break;
                }
                later = earlier;
            }
            if (torn) continue;
            if (!found) {
                out = later.s;  // older than anything kept
                return true;
            }
            const double span = later.t - earlier.t;
            const double w = span > 0 ? (t - earlier.t) / span : 0.0;
            out = earlier.s;
            out.position = earlier.s.position + w * (later.s.position - earlier.s.position);
            out.orientation = earlier.s.orientation.slerp(w, later.s.orientation);
            return true;
        }
    }

    /// Reader: the earliest sample after time t whose button 1 is down (a grab that began while the
    /// reader was not looking), false if none is kept.
    bool firstGrabAfter(double t, DeviceSample& out) const {
        for (;;) {
            const std::uint64_t head = head_.load(std::memory_order_acquire);
            const std::uint64_t oldest = head > kSlots - 1 ? head - (kSlots - 1) : 0;
            bool found = false, torn = false;
            Sample s;
            for (std::uint64_t i = head; i > oldest;) {
                if (!read(--i, s)) {
                    torn = true;
                    break;
                }
                if (s.t <= t) break;
                if (s.s.buttons & 1u) {
                    out = s.s;
                    found = true;
                }
            }
            if (!torn) return found;
        }
    }

private:
    struct Slot {
        std::atomic<std::uint64_t> seq{0};
        std::atomic<double> v[8] = {};  // t, position, orientation (w, x, y, z)
        std::atomic<std::uint32_t> buttons{0};
    };
    struct Sample {
        double t = 0;
        DeviceSample s;
    };
    /// One slot, false if the writer was in it (or lapped it) meanwhile.
    bool read(std::uint64_t i, Sample& out) const {
        const Slot& slot = slots_[i % kSlots];
        const std::uint64_t before = slot.seq.load(std::memory_order_acquire);
        if (before & 1u) return false;
        out.t = slot.v[0].load(std::memory_order_acquire);
        for (int k = 0; k < 3; ++k) out.s.position[k] = slot.v[1 + k].load(std::memory_order_acquire);
        out.s.orientation = Eigen::Quaterniond(slot.v[4].load(std::memory_order_acquire), slot.v[5].load(std::memory_order_acquire),
                                               slot.v[6].load(std::memory_order_acquire), slot.v[7].load(std::memory_order_acquire));
        out.s.buttons = slot.buttons.load(std::memory_order_acquire);
        out.s.valid = true;
        return slot.seq.load(std::memory_order_relaxed) == before &&
               head_.load(std::memory_order_acquire) - i <= kSlots - 1;  // not lapped since
    }

    std::array<Slot, kSlots> slots_;
    std::atomic<std::uint64_t> head_{0};
};

}  // namespace hs
