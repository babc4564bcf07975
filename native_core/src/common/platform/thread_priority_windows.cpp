#include "common/platform/thread_priority.hpp"

#include <windows.h>
#include <avrt.h>
#include <timeapi.h>

#include <algorithm>

namespace hs {

PriorityGrant takeHapticPriority(bool realtime) {
    PriorityGrant out{false, "off"};
    if (!realtime) return out;
    // The multimedia class scheduler raises a "Pro Audio" thread into the real-time band for its
    // share of each period, as audio applications do; where it is missing, a time-critical thread
    // (the top of the process's priority class).
    DWORD task = 0;
    if (HANDLE h = AvSetMmThreadCharacteristicsW(L"Pro Audio", &task)) {
        AvSetMmThreadPriority(h, AVRT_PRIORITY_CRITICAL);
        out.ok = true;
        out.how = "MMCSS Pro Audio (critical)";
        return out;
    }
    const DWORD mmcss = GetLastError();
    if (SetThreadPriority(GetCurrentThread(), THREAD_PRIORITY_TIME_CRITICAL)) {
        out.ok = true;
        out.how = "THREAD_PRIORITY_TIME_CRITICAL (MMCSS: error " + std::to_string(mmcss) + ")";
    } else {
        out.how = "none: MMCSS error " + std::to_string(mmcss) + ", SetThreadPriority error " +
                  std::to_string(GetLastError());
    }
    return out;
}

PreciseWakeups::PreciseWakeups() {
    // The system timer ticks every 15.6 ms by default: a 1 ms sleep would last a tick.
    raised_ = timeBeginPeriod(1) == TIMERR_NOERROR;
}

PreciseWakeups::~PreciseWakeups() {
    if (raised_) timeEndPeriod(1);
}

void lowerThreadPriority(int steps) {
    if (steps <= 0) return;
    SetThreadPriority(GetCurrentThread(), steps >= 10 ? THREAD_PRIORITY_LOWEST : THREAD_PRIORITY_BELOW_NORMAL);
}

}  // namespace hs
