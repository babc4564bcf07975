// Lock-free single-producer / single-consumer exchange of the latest value (a triple buffer):
// the writer never waits, the reader always gets the newest complete value, and neither allocates.
#pragma once
#include <array>
#include <atomic>
#include <cstdint>

namespace hs {

template <class T>
class TripleBuffer {
public:
    TripleBuffer() = default;
    explicit TripleBuffer(const T& initial) { slots_.fill(initial); }

    /// Writer side: fill back() then publish().
    T& back() { return slots_[back_]; }
    void publish() {
        // Hand the back slot over as the middle one, flagged fresh; take the old middle as back.
        const std::uint8_t old = middle_.exchange(static_cast<std::uint8_t>(back_ | kFresh), std::memory_order_acq_rel);
        back_ = old & kIndex;
    }
    void write(const T& value) {
        back() = value;
        publish();
    }

    /// Reader side: true if a value newer than the last read arrived; front() is the newest value.
    bool update() {
        if (!(middle_.load(std::memory_order_relaxed) & kFresh)) return false;
        const std::uint8_t old = middle_.exchange(front_, std::memory_order_acq_rel);
        front_ = old & kIndex;
        return true;
    }
    const T& front() const { return slots_[front_]; }
    /// Reader side, for pre-sized buffers the reader may fill in place (e.g. to reuse storage).
    T& frontMutable() { return slots_[front_]; }
    /// Writer-side initialisation of all slots (before the threads start), e.g. to size vectors.
    template <class F>
    void forEachSlot(F&& f) {
        for (auto& s : slots_) f(s);
    }

private:
    static constexpr std::uint8_t kFresh = 4, kIndex = 3;
    std::array<T, 3> slots_{};
    std::uint8_t back_ = 0, front_ = 1;
    std::atomic<std::uint8_t> middle_{2};
};

}  // namespace hs
