// An emulated HID PID force-feedback device (3 force axes) that answers feature reports like a
// real one: Create New Effect allocates a block from a small pool, Block Load reports the index and
// status, output reports start/stop effects and set magnitudes. Used to test the PID driver without
// hardware; it parses what it receives with the same descriptor it publishes.
#pragma once
#include <array>
#include <mutex>
#include <vector>

#include "devices/hid/hid_report_descriptor.hpp"
#include "devices/hid/hid_transport.hpp"

namespace hs {

struct EmulatedEffect {
    bool allocated = false, running = false, constant = false;
    int axesMask = 0;
    std::int64_t magnitude = 0, duration = 0;
};

class PidEmulator final : public HidTransport {
public:
    explicit PidEmulator(int poolSize = 8);
    HidInfo info() const override;
    int read(std::uint8_t* buf, std::size_t size, int timeoutMs) override;
    int write(const std::uint8_t* buf, std::size_t size) override;
    int sendFeature(const std::uint8_t* buf, std::size_t size) override;
    int getFeature(std::uint8_t* buf, std::size_t size) override;
    std::vector<std::uint8_t> reportDescriptor() override { return descriptor_; }

    // inspection (any thread)
    std::vector<EmulatedEffect> effects() const;
    bool actuatorsEnabled() const;
    int stopAllCount() const;
    std::size_t outputReports() const;
    std::size_t malformedReports() const;
    /// Makes the device refuse further writes (-1), as an unplugged device does.
    void unplug();

private:
    std::vector<std::uint8_t> descriptor_;
    HidReportLayout layout_;
    mutable std::mutex mutex_;
    std::vector<EmulatedEffect> pool_;
    int lastCreated_ = 0;
    bool lastCreateOk_ = false, actuators_ = false, unplugged_ = false;
    int stopAll_ = 0;
    std::size_t outputs_ = 0, malformed_ = 0;
};

}  // namespace hs
