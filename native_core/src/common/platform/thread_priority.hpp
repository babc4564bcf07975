// The haptic thread's priority and wake-ups, and the simulation thread's lower priority, each
// system its own way (thread_priority_linux.cpp, thread_priority_windows.cpp): what a 1 kHz loop
// needs from the scheduler, said in the session status as the system granted it.
#pragma once
#include <chrono>
#include <memory>
#include <string>

namespace hs {

/// What the system granted the haptic thread.
struct PriorityGrant {
    bool ok = false;  ///< real-time (Linux: SCHED_FIFO) or time-critical (Windows)
    std::string how;  ///< how, or why not ("off" when not asked for)
};

/// Makes the calling thread the haptic loop's: with `realtime`, the highest priority this user may
/// have (Linux: SCHED_FIFO within the rtprio limit, else from RealtimeKit as desktop audio gets it;
/// Windows: the multimedia class scheduler's "Pro Audio" task, else a time-critical thread).
PriorityGrant takeHapticPriority(bool realtime);

/// Wake-ups to the millisecond or better while it lives, for the calling thread's sleeps (Linux:
/// 1 us timer slack instead of 50 us; Windows: a high-resolution waitable timer, where the system
/// has one, and the system timer at 1 ms instead of 15.6 ms).
class PreciseWakeups {
public:
    PreciseWakeups();
    ~PreciseWakeups();
    PreciseWakeups(const PreciseWakeups&) = delete;
    PreciseWakeups& operator=(const PreciseWakeups&) = delete;

    /// Sleeps the calling thread (the one that made this) until `t`.
    void sleepUntil(std::chrono::steady_clock::time_point t) const;
    /// How the thread is woken where that is worth saying (Windows: which timer), else "".
    const std::string& how() const { return how_; }

private:
    struct CloseTimer {
        void operator()(void* timer) const;
    };
    bool raised_ = false;
    std::unique_ptr<void, CloseTimer> timer_;  // (Windows: the waitable timer's handle)
    std::string how_;
};

/// Lowers the calling thread by `steps` (1..19, as nice does) below normal: the simulation's, so
/// that the haptic loop and the GUI go first on a loaded machine.
void lowerThreadPriority(int steps);

}  // namespace hs
