// A fake OpenHaptics HD library for the tests: the C calls OpenHapticsDevice loads, with the HD
// API's behaviour where it matters (a scheduler thread calling the scheduled callbacks at 1 kHz,
// frames, errors through hdGetError) over the fake mechanism. fake_hd_* calls steer it.
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <thread>

#include "fake_mechanism.hpp"

namespace {
using Callback = unsigned int (*)(void*);
struct ErrorInfo {
    unsigned int errorCode;
    int internalErrorCode;
    unsigned int hHD;
};
constexpr unsigned int kDeviceFault = 0x0300, kNotInitialised = 0x0302;

struct State {
    std::mutex lock;  // the scheduler thread and the test's calls
    fake::Mechanism mechanism;
    std::thread scheduler;
    std::atomic<bool> running{false};
    Callback callbacks[8] = {};
    void* data[8] = {};
    bool present = true, initialised = false, forceOutput = false;
    unsigned int error = 0;
    long frames = 0, unplugAfter = -1, nanEvery = 0;
    double pendingForce[3] = {0, 0, 0};
    ~State() {  // (unloaded with the scheduler still up: a test that failed half-way)
        running.store(false);
        if (scheduler.joinable()) scheduler.join();
    }
};
State& state() {
    static State s;
    return s;
}

void schedulerLoop() {
    State& s = state();
    auto next = std::chrono::steady_clock::now();
    while (s.running.load()) {
        next += std::chrono::milliseconds(1);
        for (int k = 0; k < 8; ++k) {
            Callback cb;
            void* d;
            {
                std::lock_guard<std::mutex> g(s.lock);
                cb = s.callbacks[k];
                d = s.data[k];
            }
            if (cb && cb(d) == 0) {
                std::lock_guard<std::mutex> g(s.lock);
                s.callbacks[k] = nullptr;
            }
        }
        std::this_thread::sleep_until(next);
    }
}
}  // namespace

extern "C" {
unsigned int hdInitDevice(const char*) {
    State& s = state();
    std::lock_guard<std::mutex> g(s.lock);
    if (!s.present) {
        s.error = kDeviceFault;
        return 0xFFFFFFFF;
    }
    s.initialised = true;
    s.error = 0;
    return 1;
}
void hdDisableDevice(unsigned int) {
    std::lock_guard<std::mutex> g(state().lock);
    state().initialised = false;
    state().forceOutput = false;
}
ErrorInfo hdGetError() {
    State& s = state();
    std::lock_guard<std::mutex> g(s.lock);
    const ErrorInfo e{s.error, s.error ? -1 : 0, 1};
    s.error = 0;  // as the HD API: the error is taken off its stack
    return e;
}
const char* hdGetErrorString(unsigned int code) {
    return code == kDeviceFault ? "HD_DEVICE_FAULT" : code == kNotInitialised ? "HD_NOT_INITIALISED" : "HD_SUCCESS";
}
void hdEnable(unsigned int cap) {
    std::lock_guard<std::mutex> g(state().lock);
    if (cap == 0x4000) state().forceOutput = true;
}
void hdStartScheduler() {
    State& s = state();
    if (s.running.exchange(true)) return;
    s.scheduler = std::thread(schedulerLoop);
}
void hdStopScheduler() {
    State& s = state();
    if (!s.running.exchange(false)) return;
    s.scheduler.join();
}
unsigned long hdScheduleAsynchronous(Callback cb, void* data, unsigned short) {
    State& s = state();
    std::lock_guard<std::mutex> g(s.lock);
    for (int k = 0; k < 8; ++k)
        if (!s.callbacks[k]) {
            s.callbacks[k] = cb;
            s.data[k] = data;
            return static_cast<unsigned long>(k + 1);
        }
    return 0;
}
void hdUnschedule(unsigned long handle) {
    std::lock_guard<std::mutex> g(state().lock);
    if (handle >= 1 && handle <= 8) state().callbacks[handle - 1] = nullptr;
}
void hdBeginFrame(unsigned int) {}
void hdEndFrame(unsigned int) {
    State& s = state();
    std::lock_guard<std::mutex> g(s.lock);
    if (!s.initialised) {
        s.error = kNotInitialised;
        return;
    }
    if (s.unplugAfter >= 0 && s.frames >= s.unplugAfter) {
        s.error = kDeviceFault;  // unplugged: no more frames
        for (double& f : s.mechanism.force) f = 0;
        return;
    }
    for (int i = 0; i < 3; ++i) s.mechanism.force[i] = s.forceOutput ? s.pendingForce[i] : 0.0;
    s.mechanism.step();
    ++s.frames;
}
void hdGetDoublev(unsigned int what, double* v) {
    State& s = state();
    std::lock_guard<std::mutex> g(s.lock);
    if (what == 0x2050) {  // HD_CURRENT_POSITION, mm
        for (int i = 0; i < 3; ++i) v[i] = 1000 * s.mechanism.tip[i];
        if (s.nanEvery > 0 && s.frames % s.nanEvery == 0) v[1] = NAN;
    } else if (what == 0x2603) {  // HD_NOMINAL_MAX_FORCE, N
        v[0] = 3.3;
    } else if (what == 0x2602) {  // HD_NOMINAL_MAX_STIFFNESS, N/mm
        v[0] = 0.9;
    }
}
void hdGetIntegerv(unsigned int what, int* v) {
    std::lock_guard<std::mutex> g(state().lock);
    if (what == 0x2000) v[0] = state().mechanism.buttons();
}
void hdSetDoublev(unsigned int what, const double* v) {
    std::lock_guard<std::mutex> g(state().lock);
    if (what == 0x2700)
        for (int i = 0; i < 3; ++i) state().pendingForce[i] = v[i];
}
const char* hdGetString(unsigned int what) { return what == 0x2501 ? "Touch" : ""; }

// --- the test's handles ---
void fake_hd_reset() {
    hdStopScheduler();
    State& s = state();
    std::lock_guard<std::mutex> g(s.lock);
    s.mechanism.reset();
    for (auto& c : s.callbacks) c = nullptr;
    s.present = true;
    s.initialised = s.forceOutput = false;
    s.error = 0;
    s.frames = 0;
    s.unplugAfter = -1;
    s.nanEvery = 0;
    for (double& f : s.pendingForce) f = 0;
}
void fake_hd_script(const double* rows, int n) {
    std::lock_guard<std::mutex> g(state().lock);
    state().mechanism.setScript(rows, n);
}
void fake_hd_present(int present) {
    std::lock_guard<std::mutex> g(state().lock);
    state().present = present != 0;
}
void fake_hd_unplug_after(long frames) {
    std::lock_guard<std::mutex> g(state().lock);
    state().unplugAfter = frames;
}
void fake_hd_nan_every(long n) {
    std::lock_guard<std::mutex> g(state().lock);
    state().nanEvery = n;
}
// tip (mm), largest force seen (N), frames run, whether the scheduler still runs
void fake_hd_observe(double* tipMm, double* largestForce, long* frames, int* schedulerRunning) {
    State& s = state();
    std::lock_guard<std::mutex> g(s.lock);
    for (int i = 0; i < 3; ++i) tipMm[i] = 1000 * s.mechanism.tip[i];
    *largestForce = s.mechanism.largestForce;
    *frames = s.frames;
    *schedulerRunning = s.running.load() ? 1 : 0;
}
}
