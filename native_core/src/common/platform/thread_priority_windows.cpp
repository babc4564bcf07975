#include "common/platform/thread_priority.hpp"

#include <windows.h>
#include <avrt.h>
#include <timeapi.h>

#include <algorithm>
#include <thread>

#ifndef CREATE_WAITABLE_TIMER_HIGH_RESOLUTION  // (Windows 10 1803's; MinGW-w64 10's headers lack it)
#define CREATE_WAITABLE_TIMER_HIGH_RESOLUTION 0x00000002
#endif

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
    // A high-resolution waitable timer (Windows 10 1803 on) wakes within tenths of a millisecond,
    // where Sleep waits for the system timer's next tick.
    if (HANDLE h = CreateWaitableTimerExW(nullptr, nullptr, CREATE_WAITABLE_TIMER_HIGH_RESOLUTION, TIMER_ALL_ACCESS)) {
        timer_.reset(h);
        how_ = "wakes by a high-resolution waitable timer";
    } else if (HANDLE plain = CreateWaitableTimerExW(nullptr, nullptr, 0, TIMER_ALL_ACCESS)) {
        timer_.reset(plain);
        how_ = "wakes by a waitable timer (no high-resolution one: error " + std::to_string(GetLastError()) + ")";
    } else {
        how_ = "wakes by Sleep";
    }
    if (raised_) how_ += ", system timer at 1 ms";
}

PreciseWakeups::~PreciseWakeups() {
    if (raised_) timeEndPeriod(1);
}

void PreciseWakeups::CloseTimer::operator()(void* timer) const { CloseHandle(timer); }

void PreciseWakeups::sleepUntil(std::chrono::steady_clock::time_point t) const {
    const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(t - std::chrono::steady_clock::now());
    if (left.count() <= 0) return;
    LARGE_INTEGER due;
    due.QuadPart = -static_cast<LONGLONG>((left.count() + 99) / 100);  // (negative: relative, in 100 ns)
    if (timer_ && SetWaitableTimer(timer_.get(), &due, 0, nullptr, nullptr, FALSE)) {
        WaitForSingleObject(timer_.get(), INFINITE);
        return;
    }
    std::this_thread::sleep_until(t);
}

void lowerThreadPriority(int steps) {
    if (steps <= 0) return;
    SetThreadPriority(GetCurrentThread(), steps >= 10 ? THREAD_PRIORITY_LOWEST : THREAD_PRIORITY_BELOW_NORMAL);
}

}  // namespace hs
