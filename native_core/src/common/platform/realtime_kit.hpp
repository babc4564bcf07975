// Real-time priority without root, the way audio applications get it: RealtimeKit (rtkit-daemon,
// org.freedesktop.RealtimeKit1 on the system bus) makes a thread SCHED_FIFO for a user whose rtprio
// limit does not allow it, within its own limits: a priority up to its MaxRealtimePriority, and only
// for a process whose RLIMIT_RTTIME is at most its RTTimeUSecMax (so a runaway real-time thread is
// stopped by the kernel rather than freeze the machine).
#pragma once
#include <string>

namespace hs {

/// What RealtimeKit answered.
struct RealtimeGrant {
    bool granted = false;
    int priority = 0;  ///< the SCHED_FIFO priority granted
    std::string why;   ///< why not, where not
};

/// Asks RealtimeKit on the bus at `busAddress` to make thread `tid` of this process SCHED_FIFO at
/// `priority` (lowered to what it allows), after lowering this process's RLIMIT_RTTIME to what it
/// asks for. Blocks up to about `timeout` seconds per message; never throws.
RealtimeGrant askRealtimeKit(long tid, int priority, const std::string& busAddress, double timeout);

}  // namespace hs
