// Touch/Phantom (OpenHaptics) and Force Dimension (DHD) through their vendors' C calls, loaded at
// run time by the same dlopen path a real installation takes, here from fake libraries built with
// the tests (fake_vendor/): position in, force out, buttons, a spring held in a closed loop, a
// replayed rope stroke in a threaded session, the device unplugged, malformed positions, a
// missing library, a library without the calls, no device attached; no allocation per tick.
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <thread>
#include <type_traits>

#include "device_session.hpp"
#include "common/platform/shared_library.hpp"
#include "devices/device_limits.hpp"
#include "devices/vendor/dhd_device.hpp"
#include "solvers/dynamic_surface.hpp"
#include "runtime/haptic_runtime.hpp"
#include "devices/vendor/openhaptics_device.hpp"

using namespace hs;

namespace {
const std::string kHd = std::string(HS_FAKE_VENDOR_DIR) + "/libHD" + HS_MODULE_SUFFIX;
const std::string kDhd = std::string(HS_FAKE_VENDOR_DIR) + "/libdhd" + HS_MODULE_SUFFIX;

// The fake library's own handles (the same loaded copy the device uses: same path, same handle).
class Fake {
public:
    Fake(const std::string& path, const char* prefix) : library_(SharedLibrary::open({path}, "the fake library")), prefix_(prefix) {
        call<void (*)()>("reset")();
    }
    template <class F>
    F call(const char* what) const {
        return library_.function<F>((prefix_ + what).c_str());
    }
    void script(const std::vector<double>& rows) const {
        call<void (*)(const double*, int)>("script")(rows.data(), static_cast<int>(rows.size() / 5));
    }
    struct Seen {
        Vec3 tipMm;
        double largestForce;
        long frames;
        int live;
    };
    Seen observe() const {
        Seen s{};
        call<void (*)(double*, double*, long*, int*)>("observe")(s.tipMm.data(), &s.largestForce, &s.frames, &s.live);
        return s;
    }

private:
    SharedLibrary library_;
    std::string prefix_;
};

VendorDeviceSettings settingsFor(const std::string& library) {
    VendorDeviceSettings s;
    s.library = {library};
    return s;
}

// A stroke in each device's own frame: the hand takes the grip 20 mm "up" over 0.6 s with the
// first button held, lets go at 0.8 s. up: the device axis that is the document's z.
std::vector<double> strokeUp(int up) {
    std::vector<double> rows;
    for (double t : {0.0, 0.6, 0.8, 5.0}) {
        double p[3] = {0, 0, 0};
        p[up] = 0.02 * std::min(1.0, t / 0.6);
        rows.insert(rows.end(), {t, p[0], p[1], p[2], t < 0.8 ? 1.0 : 0.0});
    }
    return rows;
}

// Calls f once per device frame, n times: OpenHaptics' frames come from its scheduler thread
// (wait for the next), DHD's from each poll.
template <class D, class F>
void everyFrame(D& dev, int n, F&& f) {
    for (int k = 0; k < n; ++k) {
        if constexpr (std::is_same_v<D, OpenHapticsDevice>) {
            const std::uint64_t seen = dev.frames();
            while (dev.frames() == seen) std::this_thread::yield();
        }
        f();
    }
}

// Holds a spring of 400 N/m towards the middle against a hand 20 mm up through its own 300 N/m
// spring: the grip settles where the two balance (3/7 of the way), through the force out.
template <class D>
void holdsASpring(D& dev, double tolerance) {
    DeviceSample s;
    everyFrame(dev, 3000, [&] {
        ASSERT_TRUE(dev.sample(0, s));
        dev.setForce(-400.0 * s.position);  // mN/mm = N/m
    });
    EXPECT_NEAR(s.position.z(), 20.0 * 300 / 700, tolerance);
}

}  // namespace

TEST(VendorDevices, AMissingLibraryOrCallIsAClearError) {
    try {
        OpenHapticsDevice dev(settingsFor("/nonexistent/libHD.so"));
        FAIL() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("OpenHaptics"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("/nonexistent/libHD.so"), std::string::npos) << e.what();
    }
    try {
        OpenHapticsDevice dev(settingsFor(kDhd));  // loads, but it is not OpenHaptics
        FAIL() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("has no symbol hdInitDevice"), std::string::npos) << e.what();
    }
    try {
        DhdDevice dev(settingsFor(kHd));
        FAIL() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("has no symbol dhdGetDeviceCount"), std::string::npos) << e.what();
    }
}

TEST(VendorDevices, OpenHapticsTracksTheStylusAndRendersASpring) {
    Fake fake(kHd, "fake_hd_");
    fake.script({0, 0, 0.02, 0, 1});  // the hand holds the stylus 20 mm up (HD: y up), button 1
    OpenHapticsDevice dev(settingsFor(kHd));
    dev.start();
    EXPECT_EQ(dev.model(), "Touch");
    const DeviceCaps caps = dev.caps();
    EXPECT_TRUE(caps.forceOutput);
    EXPECT_NEAR(caps.maxForce, 3300, 1e-9);  // mN: the device's nominal 3.3 N
    // the table's bound for a Touch at 1 kHz (400 N/m), below the device's nominal 900 N/m
    EXPECT_NEAR(caps.maxStiffness, passiveStiffnessFor(limitsFor("Touch"), 1000), 1e-9);
    DeviceSample s;
    ASSERT_TRUE(dev.sample(0, s));
    EXPECT_EQ(s.buttons, 1u);
    holdsASpring(dev, 0.5);
    const Fake::Seen seen = fake.observe();
    EXPECT_GT(seen.largestForce, 3.0);  // N: the motors did the holding
    EXPECT_NEAR(s.position.x(), seen.tipMm.x(), 1e-9);
    dev.stop();
    EXPECT_EQ(fake.observe().live, 0);  // the scheduler stopped
}

TEST(VendorDevices, DhdTracksTheGripAndRendersASpring) {
    Fake fake(kDhd, "fake_dhd_");
    fake.script({0, 0, 0, 0.02, 2});  // DHD: z up; the second button
    DhdDevice dev(settingsFor(kDhd));
    dev.start();
    EXPECT_EQ(dev.model(), "omega.3");
    EXPECT_NEAR(dev.caps().maxStiffness, 5000, 1e-9);  // N/m = mN/mm: omega.3's row at 1 kHz
    DeviceSample s;
    ASSERT_TRUE(dev.sample(0, s));
    EXPECT_EQ(s.buttons, 2u);
    holdsASpring(dev, 0.3);
    EXPECT_GT(fake.observe().largestForce, 3.0);
    dev.stop();
    EXPECT_EQ(fake.observe().live, 0);  // closed
}

TEST(VendorDevices, TheDocumentFrameIsTheFrontView) {
    // right, up, towards the user in each device's frame -> the document's x, z, -y
    Fake hd(kHd, "fake_hd_");
    hd.script({0, 0.01, 0.02, 0.03, 0});
    OpenHapticsDevice touch(settingsFor(kHd));
    touch.start();
    DeviceSample s;
    everyFrame(touch, 5, [&] { touch.sample(0, s); });
    EXPECT_NEAR(s.position.x(), 10, 1e-6);
    EXPECT_NEAR(s.position.z(), 20, 1e-6);
    EXPECT_NEAR(s.position.y(), -30, 1e-6);
    touch.stop();
    Fake dhd(kDhd, "fake_dhd_");
    dhd.script({0, 0.03, 0.01, 0.02, 0});  // DHD: x towards the user, y right, z up
    DhdDevice omega(settingsFor(kDhd));
    omega.start();
    ASSERT_TRUE(omega.sample(0, s));
    EXPECT_NEAR(s.position.x(), 10, 1e-6);
    EXPECT_NEAR(s.position.z(), 20, 1e-6);
    EXPECT_NEAR(s.position.y(), -30, 1e-6);
}

TEST(VendorDevices, MalformedPositionsKeepTheLastGoodOne) {
    Fake hd(kHd, "fake_hd_");
    hd.script({0, 0.01, 0, 0, 0});
    hd.call<void (*)(long)>("nan_every")(7);
    OpenHapticsDevice touch(settingsFor(kHd));
    touch.start();
    DeviceSample s;
    everyFrame(touch, 100, [&] {
        ASSERT_TRUE(touch.sample(0, s));
        ASSERT_TRUE(s.position.allFinite());
    });
    EXPECT_GT(touch.malformed(), 5u);
    EXPECT_NEAR(s.position.x(), 10, 0.5);
    touch.stop();
    Fake dhd(kDhd, "fake_dhd_");
    dhd.script({0, 0, 0.01, 0, 0});
    dhd.call<void (*)(long)>("nan_every")(7);
    DhdDevice omega(settingsFor(kDhd));
    omega.start();
    for (int k = 0; k < 200; ++k) {
        ASSERT_TRUE(omega.sample(0, s));
        ASSERT_TRUE(s.position.allFinite());
    }
    EXPECT_EQ(omega.malformed(), 28u);
    EXPECT_NEAR(s.position.x(), 10, 0.5);
}

TEST(VendorDevices, NoDeviceAttachedSaysSo) {
    Fake hd(kHd, "fake_hd_");
    hd.call<void (*)(int)>("present")(0);
    OpenHapticsDevice touch(settingsFor(kHd));
    try {
        touch.start();
        FAIL() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("HD_DEVICE_FAULT"), std::string::npos) << e.what();
    }
    Fake dhd(kDhd, "fake_dhd_");
    dhd.call<void (*)(int)>("devices")(0);
    DhdDevice omega(settingsFor(kDhd));
    try {
        omega.start();
        FAIL() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("no device attached"), std::string::npos) << e.what();
    }
}

TEST(VendorDevices, ATickDoesNotAllocate) {
    Fake hd(kHd, "fake_hd_");
    OpenHapticsDevice touch(settingsFor(kHd));
    touch.start();
    Fake dhd(kDhd, "fake_dhd_");
    DhdDevice omega(settingsFor(kDhd));
    omega.start();
    DeviceSample s;
    touch.sample(0, s);
    omega.sample(0, s);
    const long before = allocationCount();
    for (int k = 0; k < 200; ++k) {
        touch.sample(0, s);
        touch.setForce(Vec3(100, -200, 300));
        omega.sample(0, s);
        omega.setForce(Vec3(100, -200, 300));
    }
    EXPECT_EQ(allocationCount() - before, 0);
    touch.stop();
}

TEST(VendorDevices, OpenHapticsRopeStrokeInAThreadedSessionThenUnplugged) {
    Fake fake(kHd, "fake_hd_");
    fake.script(strokeUp(1));
    fake.call<void (*)(long)>("unplug_after")(1400);
    auto dev = std::make_shared<OpenHapticsDevice>(settingsFor(kHd));
    const SessionOutcome out = sessionUntilItStops(dev);
    EXPECT_NEAR(out.used.maxForce, 3300, 1e-9);  // mN: the Touch's, as it reported itself on opening
    expectLostAfterAStroke(out);
    const Fake::Seen seen = fake.observe();
    EXPECT_GT(seen.largestForce, 0.01);  // N: and pulled the stylus back
    EXPECT_EQ(seen.live, 0);             // a clean stop: the scheduler is down
}

TEST(VendorDevices, DhdRopeStrokeInAThreadedSessionThenUnplugged) {
    Fake fake(kDhd, "fake_dhd_");
    fake.script(strokeUp(2));
    fake.call<void (*)(long)>("unplug_after")(1400);
    auto dev = std::make_shared<DhdDevice>(settingsFor(kDhd));
    const SessionOutcome out = sessionUntilItStops(dev);
    // the omega.3's limits, known once it was opened (before: the softest row's)
    EXPECT_NEAR(out.used.maxStiffness, 5000, 1e-9);
    EXPECT_NEAR(out.used.maxForce, 12000, 1e-9);
    expectLostAfterAStroke(out);
    const Fake::Seen seen = fake.observe();
    EXPECT_GT(seen.largestForce, 0.01);
    EXPECT_EQ(seen.live, 0);  // closed
}
