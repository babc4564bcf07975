#include "common/platform/thread_priority.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <thread>

#include "common/platform/dbus_connection.hpp"
#include "common/platform/realtime_kit.hpp"

namespace hs {

PriorityGrant takeHapticPriority(bool realtime) {
    PriorityGrant out{false, "off"};
    if (!realtime) return out;
    // Below the top priority, and within the user's rtprio limit where one is set (a line in
    // /etc/security/limits.d grants it without root): asking for more than the limit fails.
    const int top = sched_get_priority_max(SCHED_FIFO) - 1;
    int priority = top;
    rlimit limit{};
    if (geteuid() != 0 && getrlimit(RLIMIT_RTPRIO, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
        priority = std::min(priority, static_cast<int>(limit.rlim_cur));
    sched_param sp{};
    sp.sched_priority = priority;
    const int refused = priority >= 1 ? pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp) : EPERM;
    if (refused == 0) {
        out.ok = true;
        out.how = "SCHED_FIFO " + std::to_string(priority) + (geteuid() == 0 ? " (root)" : " (rtprio limit)");
        return out;
    }
    // Where the limit does not allow it, RealtimeKit may (a desktop's audio runs so).
    const std::string why = priority < 1 ? "the rtprio limit is 0" : std::string("SCHED_FIFO: ") + std::strerror(refused);
    const RealtimeGrant g = askRealtimeKit(static_cast<long>(syscall(SYS_gettid)), top,
                                           DBusConnection::systemBusAddress(), 0.5);
    int policy = SCHED_OTHER;
    out.ok = g.granted && pthread_getschedparam(pthread_self(), &policy, &sp) == 0 &&
             (policy & ~SCHED_RESET_ON_FORK) == SCHED_FIFO;  // (rtkit sets that flag too)
    out.how = out.ok ? "SCHED_FIFO " + std::to_string(sp.sched_priority) + " from RealtimeKit"
                     : "none: " + why + "; RealtimeKit: " + (g.granted ? "granted, but the thread is not SCHED_FIFO" : g.why);
    return out;
}

PreciseWakeups::PreciseWakeups() {
    // A thread's timer slack (50 us by default) delays every wake-up; it ends with the thread.
    raised_ = prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL) == 0;
}

PreciseWakeups::~PreciseWakeups() = default;

void PreciseWakeups::CloseTimer::operator()(void*) const {}  // (no timer handle on Linux)

void PreciseWakeups::sleepUntil(std::chrono::steady_clock::time_point t) const { std::this_thread::sleep_until(t); }

void lowerThreadPriority(int steps) {
    if (steps > 0) setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), std::min(steps, 19));
}

}  // namespace hs
