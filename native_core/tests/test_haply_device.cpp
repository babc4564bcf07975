// Haply's Inverse3 through the Inverse Service's WebSocket JSON, against a mock service on
// loopback (haply_mock_service.hpp): discovery, the first command's session profile and basis,
// position in, force out, buttons, a spring held in a closed loop, malformed replies, a rope
// stroke in a threaded session, the link dropped, the device missing or in use; no allocation per
// tick in any thread once connected.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <thread>

#include "device_session.hpp"
#include "solvers/dynamic_surface.hpp"
#include "devices/haply/haply_device.hpp"
#include "haply_mock_service.hpp"
#include "runtime/haptic_runtime.hpp"

using namespace hs;

namespace {
// The Inverse3's cursor at rest (Haply's example inventory), and the hand's script around it.
constexpr double kRest[3] = {0.0, -0.12, 0.15};

void script(haply::MockService& service, const std::vector<std::array<double, 5>>& rows) {  // t, dx, dy, dz, buttons
    std::vector<double> flat;
    for (const auto& r : rows) flat.insert(flat.end(), {r[0], kRest[0] + r[1], kRest[1] + r[2], kRest[2] + r[3], r[4]});
    std::lock_guard<std::recursive_mutex> g(service.lock);
    service.mechanism.setScript(flat.data(), static_cast<int>(rows.size()));
}

HaplySettings at(const haply::MockService& service) {
    HaplySettings s;
    s.port = service.port();
    return s;
}

// One tick as the haptic loop does it, then the wait for the reply (a state or a malformed one).
void tick(HaplyDevice& dev, DeviceSample& s, const Vec3& force) {
    const std::uint64_t before = dev.updates() + dev.malformed();
    ASSERT_TRUE(dev.sample(0, s));
    dev.setForce(force);
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    while (dev.updates() + dev.malformed() == before && std::chrono::steady_clock::now() < end) std::this_thread::yield();
}
}  // namespace

TEST(HaplyDevice, DiscoversTheServicesDevicesOrSaysItIsNotRunning) {
    int port = 0;
    {
        haply::MockService service({"049D", "04BA"});
        port = service.port();
        const auto found = HaplyDevice::discover("127.0.0.1", port);
        ASSERT_EQ(found.size(), 2u);
        EXPECT_EQ(found[1].deviceId, "04BA");
        EXPECT_TRUE(found[0].ready);
        EXPECT_FALSE(found[0].inUse);
    }
    // (the service gone from that port)
    EXPECT_NE(errorOf([&] { HaplyDevice::discover("127.0.0.1", port, 0.5); }).find("Inverse Service"), std::string::npos);
    HaplySettings s;
    s.port = port;
    s.connectTimeout = 0.5;
    HaplyDevice dev(s);
    EXPECT_NE(errorOf([&] { dev.start(); }).find("Inverse Service"), std::string::npos);
}

TEST(HaplyDevice, TracksTheCursorAndRendersASpring) {
    haply::MockService service;
    script(service, {{0, 0, 0, 0, 0}, {0.001, 0, 0, 0.02, 1}});  // the hand lifts the grip 20 mm, button held
    HaplySettings settings = at(service);
    settings.maxForce = 8;  // N (unrated by default: the softest row's 3.3 N would clamp this spring at 9 mm)
    HaplyDevice dev(settings);
    dev.start();
    EXPECT_EQ(dev.deviceId(), "049D");
    {
        std::lock_guard<std::recursive_mutex> g(service.lock);
        EXPECT_NE(service.firstCommand.find("\"profile\""), std::string::npos) << service.firstCommand;
        EXPECT_NE(service.firstCommand.find("\"permutation\":\"XYZ\""), std::string::npos) << service.firstCommand;
    }
    DeviceSample s;
    for (int k = 0; k < 3000; ++k) tick(dev, s, -400.0 * s.position);  // mN/mm = 400 N/m towards the start
    EXPECT_NEAR(s.position.z(), 20.0 * 300 / 700, 0.3);  // the two springs' balance (Haply's z is up)
    EXPECT_NEAR(s.position.x(), 0.0, 1e-6);
    EXPECT_EQ(s.buttons, 1u);
    std::lock_guard<std::recursive_mutex> g(service.lock);
    EXPECT_GT(service.mechanism.largestForce, 2.5);  // N
    EXPECT_EQ(service.repliesSent, service.commands);  // one state per message
}

TEST(HaplyDevice, MalformedRepliesAreCountedAndSkipped) {
    haply::MockService service;
    script(service, {{0, 0, 0, 0, 0}, {0.001, 0.01, 0, 0, 0}});
    service.malformedEvery = 7;
    HaplyDevice dev(at(service));
    dev.start();
    DeviceSample s;
    for (int k = 0; k < 1500; ++k) {
        tick(dev, s, Vec3::Zero());
        ASSERT_TRUE(s.position.allFinite());
    }
    EXPECT_GT(dev.malformed(), 150u);
    EXPECT_NEAR(s.position.x(), 10.0, 0.5);  // still tracking
}

TEST(HaplyDevice, AMissingOrBusyDeviceSaysSo) {
    haply::MockService service;
    HaplySettings s = at(service);
    s.deviceId = "0000";
    HaplyDevice missing(s);
    EXPECT_NE(errorOf([&] { missing.start(); }).find("lists no Inverse3 0000"), std::string::npos);
    service.inUse = true;
    HaplyDevice busy(at(service));
    EXPECT_NE(errorOf([&] { busy.start(); }).find("in use"), std::string::npos);
    haply::MockService empty(std::vector<std::string>{});
    HaplyDevice none(at(empty));
    EXPECT_NE(errorOf([&] { none.start(); }).find("lists no Inverse3"), std::string::npos);
}

TEST(HaplyDevice, ATickDoesNotAllocateInAnyThread) {
    haply::MockService service;
    HaplyDevice dev(at(service));
    dev.start();
    DeviceSample s;
    for (int k = 0; k < 50; ++k) tick(dev, s, Vec3(100, -200, 300));
    const long before = allocationCount();
    for (int k = 0; k < 300; ++k) tick(dev, s, Vec3(100, -200, 300));
    EXPECT_EQ(allocationCount() - before, 0);
}

TEST(HaplyDevice, ARopeStrokeInAThreadedSessionThenTheLinkDrops) {
    haply::MockService service;
    // the hand takes the grip 20 mm up over 0.6 s with the button held, lets go at 0.8 s
    script(service, {{0, 0, 0, 0, 1}, {0.6, 0, 0, 0.02, 1}, {0.8, 0, 0, 0.02, 0}, {5, 0, 0, 0.02, 0}});
    service.closeAfter = 1400;
    service.realTime = true;
    // (Wine's sockets on a loaded machine stalled past the 0.1 s the device waits by default before
    // it counts itself lost, and the session ended before the stroke: the test is about the stroke
    // and the drop, so it waits half a second)
    HaplySettings settings = at(service);
    settings.staleAfter = 0.5;
    expectLostAfterAStroke(sessionUntilItStops(std::make_shared<HaplyDevice>(settings)));
    std::lock_guard<std::recursive_mutex> g(service.lock);
    EXPECT_GT(service.mechanism.largestForce, 0.05);  // and pulled the grip back
}

TEST(HaplyMessages, ReadsTheDocumentedShapes) {
    auto load = [](const char* name, haply::Reader& r) {
        std::ifstream in(std::string(HS_FIXTURES) + "/../haply/" + name);
        const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        EXPECT_FALSE(text.empty()) << name;
        std::memcpy(r.buffer(), text.data(), text.size());
        return text.size();
    };
    haply::Reader reader;
    std::vector<haply::Inverse3Info> devices;
    std::string why;
    ASSERT_TRUE(reader.inventory(load("inventory.json", reader), devices, why)) << why;
    ASSERT_EQ(devices.size(), 1u);
    EXPECT_EQ(devices[0].deviceId, "049D");
    EXPECT_TRUE(devices[0].ready && devices[0].calibrated && !devices[0].inUse);
    haply::State s;
    ASSERT_TRUE(reader.state(load("state.json", reader), "049D", s));
    EXPECT_TRUE(s.found);
    EXPECT_DOUBLE_EQ(s.position.z(), 0.161);
    EXPECT_DOUBLE_EQ(s.velocity.x(), 0.01);
    EXPECT_EQ(s.buttons, 1u);  // a wireless grip's "a"
    EXPECT_FALSE(reader.state(load("state.json", reader), "04BA", s));  // not that device
    const std::size_t n = load("inventory.json", reader) - 40;  // cut short
    EXPECT_FALSE(reader.state(n, "049D", s));
    char out[512];
    const std::size_t k = haply::writeForceCommand(out, sizeof out, "049D", Vec3(0.5, NAN, 1), false);
    EXPECT_EQ(std::string(out, k),
              "{\"inverse3\":[{\"device_id\":\"049D\",\"commands\":{\"set_cursor_force\":{\"vector\":{\"x\":0,\"y\":0,\"z\":0}}}}]}");
    // any finite force fits, in a form JSON reads (the fuzz harness found %f's 300 digits for 1e300)
    EXPECT_GT(haply::writeForceCommand(out, sizeof out, "049D", Vec3(1e300, -1e-300, 2.5), false), 0u);
    EXPECT_EQ(haply::writeForceCommand(out, 20, "049D", Vec3::Zero(), true), 0u);  // does not fit
}
