// A fake Force Dimension DHD library for the tests: the C calls DhdDevice loads over the fake
// mechanism, polled (one 1 ms step of device time per dhdGetPosition, as a 1 kHz loop polls it).
// Positions in m, forces in N, in DHD's frame. fake_dhd_* calls steer it.
#include <cmath>
#include <mutex>

#include "fake_mechanism.hpp"

namespace {
struct State {
    std::mutex lock;
    fake::Mechanism mechanism;
    int devices = 1;
    bool open = false, forceEnabled = false;
    long polls = 0, unplugAfter = -1, nanEvery = 0;
    const char* error = "";
};
State& state() {
    static State s;
    return s;
}
bool unplugged(const State& s) { return s.unplugAfter >= 0 && s.polls >= s.unplugAfter; }
}  // namespace

extern "C" {
int dhdGetDeviceCount() {
    std::lock_guard<std::mutex> g(state().lock);
    return state().devices;
}
int dhdOpen() {
    State& s = state();
    std::lock_guard<std::mutex> g(s.lock);
    if (s.devices < 1) {
        s.error = "no device found";
        return -1;
    }
    s.open = true;
    return 0;
}
int dhdClose(char) {
    std::lock_guard<std::mutex> g(state().lock);
    state().open = state().forceEnabled = false;
    return 0;
}
int dhdEnableForce(unsigned char on, char) {
    std::lock_guard<std::mutex> g(state().lock);
    if (!state().open) return -1;
    state().forceEnabled = on != 0;
    return 0;
}
int dhdGetPosition(double* x, double* y, double* z, char) {
    State& s = state();
    std::lock_guard<std::mutex> g(s.lock);
    if (!s.open || unplugged(s)) {
        s.error = "communication error";
        return -1;
    }
    s.mechanism.step();
    ++s.polls;
    *x = s.mechanism.tip[0];
    *y = s.mechanism.tip[1];
    *z = s.mechanism.tip[2];
    if (s.nanEvery > 0 && s.polls % s.nanEvery == 0) *y = NAN;
    return 0;
}
int dhdSetForce(double fx, double fy, double fz, char) {
    State& s = state();
    std::lock_guard<std::mutex> g(s.lock);
    if (!s.open || unplugged(s)) {
        s.error = "communication error";
        for (double& f : s.mechanism.force) f = 0;
        return -1;
    }
    const bool on = s.forceEnabled;
    s.mechanism.force[0] = on ? fx : 0, s.mechanism.force[1] = on ? fy : 0, s.mechanism.force[2] = on ? fz : 0;
    return 0;
}
int dhdGetButtonMask(char) {
    State& s = state();
    std::lock_guard<std::mutex> g(s.lock);
    return unplugged(s) ? -1 : s.mechanism.buttons();
}
const char* dhdGetSystemName(char) { return "omega.3"; }
const char* dhdErrorGetLastStr() {
    std::lock_guard<std::mutex> g(state().lock);
    return state().error;
}

// --- the test's handles ---
void fake_dhd_reset() {
    State& s = state();
    std::lock_guard<std::mutex> g(s.lock);
    s.mechanism.reset();
    s.mechanism.mass = 0.2;  // an omega's grip is heavier than a Touch's stylus
    s.devices = 1;
    s.open = s.forceEnabled = false;
    s.polls = 0;
    s.unplugAfter = -1;
    s.nanEvery = 0;
    s.error = "";
}
void fake_dhd_script(const double* rows, int n) {
    std::lock_guard<std::mutex> g(state().lock);
    state().mechanism.setScript(rows, n);
}
void fake_dhd_devices(int n) {
    std::lock_guard<std::mutex> g(state().lock);
    state().devices = n;
}
void fake_dhd_unplug_after(long polls) {
    std::lock_guard<std::mutex> g(state().lock);
    state().unplugAfter = polls;
}
void fake_dhd_nan_every(long n) {
    std::lock_guard<std::mutex> g(state().lock);
    state().nanEvery = n;
}
void fake_dhd_observe(double* tipMm, double* largestForce, long* polls, int* open) {
    State& s = state();
    std::lock_guard<std::mutex> g(s.lock);
    for (int i = 0; i < 3; ++i) tipMm[i] = 1000 * s.mechanism.tip[i];
    *largestForce = s.mechanism.largestForce;
    *polls = s.polls;
    *open = s.open ? 1 : 0;
}
}
