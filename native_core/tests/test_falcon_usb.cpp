// The Falcon over USB, through the libusb calls its transport loads at run time, here from a fake
// libusb (fake_vendor/fake_libusb.cpp: an FTDI bridge with the emulated Falcon behind it):
// finding it, permissions, the firmware loaded from a file (handshake, echoed chunks, a bad echo,
// a wrong image, no file), then the Falcon as a Device on that link: homing, a spring in a closed
// loop, a rope stroke in a threaded session, unplugged.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <random>
#include <thread>

#include "device_session.hpp"
#include "solvers/dynamic_surface.hpp"
#include "devices/falcon/falcon_device.hpp"
#include "common/platform/shared_library.hpp"
#include "devices/falcon/falcon_usb.hpp"
#include "runtime/haptic_runtime.hpp"

using namespace hs;

namespace {
const std::string kUsb = std::string(HS_FAKE_VENDOR_DIR) + "/libusb-fake" + HS_MODULE_SUFFIX;

class FakeUsb {
public:
    explicit FakeUsb(bool firmwareRunning) : library_(SharedLibrary::open({kUsb}, "the fake libusb")) {
        call<void (*)(int)>("reset")(firmwareRunning ? 1 : 0);
    }
    template <class F>
    F call(const char* what) const {
        return library_.function<F>((std::string("fake_usb_") + what).c_str());
    }
    struct Seen {
        Vec3 tipMm;
        double largestForce;
        long commands;
        int claimed;
    };
    Seen observe() const {
        Seen s{};
        call<void (*)(double*, double*, long*, int*)>("observe")(s.tipMm.data(), &s.largestForce, &s.commands, &s.claimed);
        return s;
    }

private:
    SharedLibrary library_;
};

std::shared_ptr<usb::Library> fakeLibusb() { return usb::Library::load({kUsb}); }

std::vector<std::uint8_t> firmwareImage() {
    std::mt19937 rng(17);
    std::vector<std::uint8_t> image(1500);  // not a multiple of the 62-byte chunks
    for (auto& b : image) b = static_cast<std::uint8_t>(rng());
    return image;
}

std::string writeFile(const std::vector<std::uint8_t>& bytes, const char* name) {
    const std::string path = testing::TempDir() + name;
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    return path;
}
}  // namespace

TEST(FalconUsb, FindsTheFalconsAndSaysWhyOneCannotBeOpened) {
    FakeUsb fake(true);
    fake.call<void (*)(int)>("devices")(2);
    auto lib = fakeLibusb();
    auto found = falcon::attachedFalcons(*lib);
    ASSERT_EQ(found.size(), 2u);  // (the fake's other USB device is not one)
    EXPECT_TRUE(found[0].openable);
    EXPECT_EQ(found[1].address, 11);
    fake.call<void (*)(int)>("denied")(1);
    found = falcon::attachedFalcons(*lib);
    EXPECT_FALSE(found[0].openable);
    EXPECT_NE(found[0].why.find("udev"), std::string::npos) << found[0].why;
    EXPECT_NE(errorOf([&] { falcon::UsbTransport t(lib); }).find("no permission"), std::string::npos);
    fake.call<void (*)(int)>("denied")(0);
    fake.call<void (*)(int)>("busy")(1);
    EXPECT_NE(errorOf([&] { falcon::UsbTransport t(lib); }).find("in use by another program"), std::string::npos);
    fake.call<void (*)(int)>("devices")(0);
    EXPECT_NE(errorOf([&] { falcon::UsbTransport t(lib); }).find("none attached"), std::string::npos);
    EXPECT_NE(errorOf([] { usb::Library::load({"/nonexistent/libusb.so"}); }).find(kWindows ? "libusb.info" : "apt install libusb-1.0-0"),
              std::string::npos);
}

TEST(FalconUsb, LoadsTheFirmwareFromTheUsersFile) {
    FakeUsb fake(false);
    const auto image = firmwareImage();
    fake.call<void (*)(const std::uint8_t*, long)>("expected_firmware")(image.data(), static_cast<long>(image.size()));
    auto lib = fakeLibusb();
    // no file: says what to give
    EXPECT_NE(errorOf([&] { falcon::openFalconUsb(lib, 0, ""); }).find("firmware is not loaded"), std::string::npos);
    EXPECT_NE(errorOf([&] { falcon::openFalconUsb(lib, 0, "/nonexistent/falcon.bin"); }).find("cannot read"), std::string::npos);
    // a file that is not the firmware: loads, but nothing runs
    auto wrong = image;
    wrong[700] ^= 1;
    EXPECT_NE(errorOf([&] { falcon::openFalconUsb(lib, 0, writeFile(wrong, "wrong.bin")); }).find("did not start"), std::string::npos);
    // an echo that does not match: refused, with the step
    fake.call<void (*)(long)>("corrupt_echo_at")(100);
    EXPECT_NE(errorOf([&] { falcon::openFalconUsb(lib, 0, writeFile(image, "falcon.bin")); }).find("firmware image"), std::string::npos);
    EXPECT_EQ(fake.call<int (*)()>("firmware_running")(), 0);
    fake.call<void (*)(long)>("corrupt_echo_at")(-1);
    // the image: it runs, and the Falcon homes and answers over the link
    auto link = falcon::openFalconUsb(lib, 0, writeFile(image, "falcon.bin"));
    EXPECT_EQ(fake.call<int (*)()>("firmware_running")(), 1);
    FalconDevice dev(link, FalconSettings{});
    dev.start();
    DeviceSample s;
    EXPECT_TRUE(dev.sample(0, s));
    dev.stop();
}

TEST(FalconUsb, TheFalconOnItsLinkHoldsASpringWithoutAllocating) {
    FakeUsb fake(true);
    fake.call<void (*)(const double*, int)>("script")(std::vector<double>{0, 0, 0.02, 0.11, 1}.data(), 1);  // 20 mm up
    FalconDevice dev(falcon::openFalconUsb(fakeLibusb(), 0, ""), FalconSettings{});
    dev.start();
    DeviceSample s;
    for (int k = 0; k < 100; ++k) dev.sample(0, s), dev.setForce(-400.0 * s.position);
    const long before = allocationCount();
    for (int k = 0; k < 2900; ++k) {
        ASSERT_TRUE(dev.sample(0, s));
        dev.setForce(-400.0 * s.position);  // mN/mm = 400 N/m towards the middle
    }
    EXPECT_EQ(allocationCount() - before, 0);
    EXPECT_NEAR(s.position.z(), 20.0 * 300 / 700, 0.3);  // the two springs' balance
    EXPECT_EQ(s.buttons, 1u);
    EXPECT_GT(fake.observe().largestForce, 3.0);
    EXPECT_EQ(dev.missed(), 0u);
}

TEST(FalconUsb, ARopeStrokeInAThreadedSessionThenUnplugged) {
    FakeUsb fake(true);
    std::vector<double> rows;
    for (double t : {0.0, 0.6, 0.8, 5.0}) rows.insert(rows.end(), {t, 0.0, 0.02 * std::min(1.0, t / 0.6), 0.11, t < 0.8 ? 1.0 : 0.0});
    fake.call<void (*)(const double*, int)>("script")(rows.data(), 4);
    fake.call<void (*)(long)>("unplug_after")(1400);
    {
        expectLostAfterAStroke(
            sessionUntilItStops(std::make_shared<FalconDevice>(falcon::openFalconUsb(fakeLibusb(), 0, ""), FalconSettings{})));
        EXPECT_GT(fake.observe().largestForce, 0.05);
    }
    EXPECT_EQ(fake.observe().claimed, 0);  // released when the device went
}
