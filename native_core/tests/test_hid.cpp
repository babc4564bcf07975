// Device layer without hardware: descriptor parsing, SpaceMouse reports from recorded fixtures
// (hid-recorder format), the HID -> FreeCAD mapping, malformed input, and the HID PID driver
// against the emulated device.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

#include "device_session.hpp"
#include "runtime/haptic_runtime.hpp"
#include "devices/hid/hid_report_descriptor.hpp"
#include "devices/hid/pid_emulator.hpp"
#include "devices/hid/pid_force.hpp"
#include "devices/hid/recorded_transport.hpp"
#include "devices/replay_device.hpp"
#include "devices/hid/spacemouse.hpp"

using namespace hs;

namespace {
HidRecording fixture(const std::string& name) {
    std::ifstream f(std::string(HS_FIXTURES) + "/" + name);
    std::stringstream s;
    s << f.rdbuf();
    return parseHidRecording(s.str());
}
}  // namespace

TEST(HidDescriptor, SpaceNavigatorLayoutFromItsRealDescriptor) {
    const HidRecording rec = fixture("spacenavigator.hid");
    ASSERT_EQ(rec.descriptor.size(), 217u);
    const HidReportLayout l = parseReportDescriptor(rec.descriptor);
    EXPECT_TRUE(l.usesReportIds);
    const HidField* x = l.find(ReportType::Input, usage(0x01, 0x30));
    ASSERT_NE(x, nullptr);
    EXPECT_EQ(x->reportId, 1);
    EXPECT_EQ(x->size, 16u);
    EXPECT_EQ(x->count, 3u);
    EXPECT_EQ(x->logicalMin, -350);
    EXPECT_EQ(x->logicalMax, 350);
    EXPECT_EQ(l.find(ReportType::Input, usage(0x01, 0x35))->reportId, 2);
    EXPECT_EQ(l.find(ReportType::Input, usage(0x09, 0x02))->reportId, 3);
    EXPECT_EQ(l.reportBytes(ReportType::Input, 1), 7u);
    EXPECT_EQ(l.reportBytes(ReportType::Input, 3), 3u);
    const HidReportLayout w = parseReportDescriptor(fixture("spacemouse_wireless.hid").descriptor);
    EXPECT_EQ(w.reportBytes(ReportType::Input, 1), 13u);  // the combined layout
}

TEST(HidDescriptor, MalformedDescriptorsAreRefusedNotCrashed) {
    EXPECT_THROW(parseReportDescriptor({0x05}), std::invalid_argument);              // truncated
    EXPECT_THROW(parseReportDescriptor({0xA1, 0x01}), std::invalid_argument);        // open collection
    EXPECT_THROW(parseReportDescriptor({0xC0}), std::invalid_argument);              // stray end
    EXPECT_THROW(parseReportDescriptor({0x85, 0x00}), std::invalid_argument);        // report id 0
    std::mt19937 rng(5);
    for (int k = 0; k < 2000; ++k) {  // random bytes: either a layout or a clear error
        std::vector<std::uint8_t> d(rng() % 64);
        for (auto& b : d) b = static_cast<std::uint8_t>(rng());
        try {
            parseReportDescriptor(d);
        } catch (const std::invalid_argument&) {
        }
    }
}

TEST(HidRecording, ParsesTheFormatAndNamesBadLines) {
    const HidRecording rec = fixture("spacenavigator.hid");
    EXPECT_EQ(rec.info.vendorId, 0x046d);
    EXPECT_EQ(rec.info.productId, 0xc626);
    EXPECT_EQ(rec.events.size(), 14u);
    EXPECT_NEAR(rec.events[1].time, 0.008, 1e-12);
    EXPECT_THROW(parseHidRecording("E: 0.1 3 01 02\n"), std::invalid_argument);
    EXPECT_THROW(parseHidRecording("E: 0.1 1 zz\n"), std::invalid_argument);
    EXPECT_THROW(parseHidRecording("E: 0.2 1 01\nE: 0.1 1 01\n"), std::invalid_argument);
}

TEST(SpaceMouse, KnownModelsCoverBothVendorFamilies) {
    EXPECT_STREQ(findSpaceMouse(0x046d, 0xc626)->name, "SpaceNavigator");
    EXPECT_NE(findSpaceMouse(0x256f, 0xc635), nullptr);
    EXPECT_NE(findSpaceMouse(0x256f, 0xc652), nullptr);
    EXPECT_EQ(findSpaceMouse(0x046d, 0xc52b), nullptr);  // a Logitech receiver, not a SpaceMouse
    EXPECT_GE(spaceMouseModels().size(), 17u);
}

TEST(SpaceMouse, SplitLayoutFromRealCaptures) {
    SpaceMouseParser p;
    for (const auto& e : fixture("spacemouse_compact.hid").events) {
        p.feed(e.bytes.data(), e.bytes.size());
        if (e.time == 0.008) {
            const auto& s = p.state();
            EXPECT_EQ(s.axes[0], 18);
            EXPECT_EQ(s.axes[2], 248);
            EXPECT_EQ(s.axes[3], 32);
            EXPECT_EQ(s.axes[5], 23);
            EXPECT_FALSE(s.combinedLayout);
        }
    }
    EXPECT_EQ(p.state().reports, 4u);
    SpaceMouseParser nav;
    std::vector<std::uint32_t> buttons;
    for (const auto& e : fixture("spacenavigator.hid").events) {
        if (nav.feed(e.bytes.data(), e.bytes.size()) && e.bytes[0] == 3) buttons.push_back(nav.state().buttons);
        if (e.time == 0.008) {
            EXPECT_EQ(nav.state().axes[4], -30);  // Ry
        }
    }
    EXPECT_EQ(buttons, (std::vector<std::uint32_t>{1, 0, 2, 0, 3, 0}));
    EXPECT_EQ(nav.state().malformed, 0u);
}

TEST(SpaceMouse, CombinedLayoutAndBattery) {
    SpaceMouseParser p;
    for (const auto& e : fixture("spacemouse_wireless.hid").events) {
        p.feed(e.bytes.data(), e.bytes.size());
        if (e.time == 0.116) {
            const auto& s = p.state();
            EXPECT_TRUE(s.combinedLayout);
            EXPECT_EQ(s.axes[0], 100);
            EXPECT_EQ(s.axes[1], -100);
            EXPECT_EQ(s.axes[2], 300);
            EXPECT_EQ(s.axes[4], 10);
            EXPECT_EQ(s.axes[5], -10);
        }
        if (e.time == 0.132) {
            EXPECT_EQ(p.state().axes[0], -350);
        }
    }
    EXPECT_EQ(p.state().ignored, 1u);  // battery
    EXPECT_EQ(p.state().buttons, 0u);
}

TEST(SpaceMouse, MalformedAndUnknownReportsAreCountedAndIgnored) {
    SpaceMouseParser p;
    const std::uint8_t shortMotion[] = {0x01, 0x10, 0x00};
    const std::uint8_t unknown[] = {0x42, 1, 2, 3};
    const std::uint8_t shortButtons[] = {0x03};
    p.feed(shortMotion, sizeof shortMotion);
    p.feed(unknown, sizeof unknown);
    p.feed(shortButtons, sizeof shortButtons);
    p.feed(nullptr, 0);
    EXPECT_EQ(p.state().malformed, 3u);
    EXPECT_EQ(p.state().unknown, 1u);
    EXPECT_EQ(p.state().axes[0], 0);
    std::mt19937 rng(11);
    for (int k = 0; k < 20000; ++k) {  // garbage of every length: never reads out of bounds
        std::uint8_t buf[64];
        const std::size_t n = rng() % 65;
        for (std::size_t i = 0; i < n; ++i) buf[i] = static_cast<std::uint8_t>(rng());
        p.feed(buf, n);
    }
    const std::uint8_t enterprise[] = {0x1c, 0x03};
    SpaceMouseParser q;
    q.feed(enterprise, sizeof enterprise);
    EXPECT_EQ(q.state().buttons, 1u << 6);
    const std::uint8_t released[] = {0x1c, 0x00};
    q.feed(released, sizeof released);
    EXPECT_EQ(q.state().buttons, 0u);
}

TEST(SpaceMouse, HidFrameMapsToFreeCADByAHalfTurnAboutX) {
    // Pushing the puck right, toward the user and down; twisting clockwise seen from above.
    const std::int16_t axes[6] = {350, 350, 350, 0, 0, 175};
    double out[6];
    hidToFreeCAD(axes, 350, out);
    EXPECT_EQ(out[0], 1.0);    // right stays right
    EXPECT_EQ(out[1], -1.0);   // toward the user = -y (FreeCAD's +y points away)
    EXPECT_EQ(out[2], -1.0);   // down = -z
    EXPECT_EQ(out[5], -0.5);   // about HID +z (down) = about FreeCAD -z
    const std::int16_t beyond[6] = {900, 0, 0, 0, 0, 0};  // real units exceed the nominal range
    hidToFreeCAD(beyond, 350, out);
    EXPECT_EQ(out[0], 1.0);
}

TEST(SpaceMouse, DeviceOverARecordingInRateAndPositionControl) {
    {  // Rate control integrates a held deflection (zero-order hold): half deflection at 100 mm/s
        SpaceMouseSettings settings;
        settings.mode = SpaceMouseSettings::Mode::Rate;
        settings.translationScale = 100;
        settings.deadZone = 0.0;
        HidRecording rec;
        rec.events.push_back({0.0, {0x01, 0xaf, 0x00, 0x00, 0x00, 0x00, 0x00}});  // x = 175
        SpaceMouseDevice dev(std::make_unique<RecordedTransport>(rec, false), settings);
        dev.start();
        ASSERT_TRUE(waitFor([&] { return dev.state().reports >= 1; }));
        DeviceSample s;
        ASSERT_TRUE(dev.sample(1.0, s));
        ASSERT_TRUE(dev.sample(1.1, s));
        dev.stop();
        EXPECT_NEAR(s.position.x(), 5.0, 1e-9);
        EXPECT_EQ(dev.name(), "SpaceMouse");  // no ids in a bare recording
    }
    // Position control maps a known deflection exactly.
    SpaceMouseSettings settings;
    settings.mode = SpaceMouseSettings::Mode::Position;
    settings.deadZone = 0.0;
    settings.translationScale = 350;  // 1 mm per raw unit
    HidRecording rec;
    rec.events.push_back({0.0, {0x01, 0x12, 0x00, 0x00, 0x00, 0xf8, 0x00}});
    SpaceMouseDevice dev(std::make_unique<RecordedTransport>(rec, false), settings);
    dev.start();
    ASSERT_TRUE(waitFor([&] { return dev.state().reports >= 1; }));
    DeviceSample s;
    ASSERT_TRUE(dev.sample(0.0, s));
    dev.stop();
    EXPECT_NEAR(s.position.x(), 18.0, 1e-12);
    EXPECT_NEAR(s.position.z(), -248.0, 1e-12);
}

TEST(SpaceMouse, LossEndsTheDevice) {
    SpaceMouseDevice dev(std::make_unique<RecordedTransport>(fixture("spacenavigator.hid"), false, true), SpaceMouseSettings{});
    dev.start();
    ASSERT_TRUE(waitFor([&] { return dev.lost(); }));
    DeviceSample s;
    EXPECT_FALSE(dev.sample(0.1, s));
    dev.stop();
}

TEST(HidPid, DriverStartsStreamsAndStopsEffectsOnTheEmulator) {
    auto emu = std::make_shared<PidEmulator>();
    PidSettings settings;
    settings.fullScaleForce = 10.0;
    PidForceDriver driver(emu, settings);
    EXPECT_EQ(driver.axes(), 3);
    driver.start();
    EXPECT_TRUE(emu->actuatorsEnabled());
    auto effects = emu->effects();
    int running = 0;
    for (const auto& e : effects)
        if (e.allocated) {
            EXPECT_TRUE(e.constant);
            EXPECT_EQ(e.duration, 0xFFFF);
            running += e.running;
        }
    EXPECT_EQ(running, 3);
    driver.setForce(Vec3(5.0, -2.5, 20.0));
    EXPECT_TRUE(waitFor([&] { return emu->effects()[2].magnitude == 10000; }));  // (set by the driver's thread)
    effects = emu->effects();
    EXPECT_EQ(effects[0].magnitude, 5000);
    EXPECT_EQ(effects[1].magnitude, -2500);
    EXPECT_EQ(effects[2].magnitude, 10000);  // clamped to full scale
    EXPECT_EQ(effects[0].axesMask, 1);
    EXPECT_EQ(effects[2].axesMask, 4);
    driver.stop();
    effects = emu->effects();
    for (const auto& e : effects) {
        EXPECT_FALSE(e.running);
        EXPECT_EQ(e.magnitude, 0);
    }
    EXPECT_EQ(emu->stopAllCount(), 1);
    EXPECT_FALSE(emu->actuatorsEnabled());
    EXPECT_EQ(emu->malformedReports(), 0u);
}

TEST(HidPid, FullPoolAndMissingReportsGiveClearErrors) {
    auto tiny = std::make_shared<PidEmulator>(2);  // room for two of the three effects
    PidForceDriver driver(tiny, PidSettings{});
    EXPECT_THROW(driver.start(), std::runtime_error);
    const std::vector<std::uint8_t> notPid = fixture("spacenavigator.hid").descriptor;
    EXPECT_THROW(PidLayout::fromDescriptor(notPid), std::invalid_argument);
}

TEST(HidPid, SessionWithForceFeedbackZeroesAndStopsOnExit) {
    auto surface = std::make_shared<DynamicSurface>(BSplineSurface::plane(8, 8, 3, 3, 100, 100), 24, 24);
    auto emu = std::make_shared<PidEmulator>();
    auto driver = std::make_shared<PidForceDriver>(emu, PidSettings{});
    std::vector<double> t = {0.0, 0.5};
    Points xyz(2, 3);
    xyz << 0, 0, 0, 0, 0, 30;
    Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> q(2, 4);
    q << 1, 0, 0, 0, 1, 0, 0, 0;
    auto input = std::make_shared<ReplayDevice>(t, xyz, q, std::vector<std::uint32_t>{1, 1});
    auto device = std::make_shared<ForceFeedbackDevice>(input, driver, 50.0, 100.0);
    RuntimeSettings settings;
    HapticRuntime rt(surface, device, settings);
    rt.start();
    // The replayed cursor pulls the rope 30 mm up over 0.5 s and holds: the device pushes back.
    EXPECT_TRUE(waitFor([&] {
        bool pushing = false;
        for (const auto& e : emu->effects()) pushing |= e.running && e.magnitude != 0;
        return pushing;
    }));
    rt.stop();
    for (const auto& e : emu->effects()) EXPECT_FALSE(e.running);
    EXPECT_FALSE(emu->actuatorsEnabled());
}
