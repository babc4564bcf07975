// Haply's Inverse3 through the Inverse Service's simulation channel: a WebSocket (libwebsockets)
// to ws://host:10001 speaking its JSON (haply_messages.hpp). The service answers each message with
// one state update, so the link runs in its own I/O thread as a ping-pong paced by the haptic
// loop: each setForce wakes the I/O thread, which sends that force as the next command; each
// state update is published to the haptic loop through a triple buffer. Neither thread takes the
// GIL or allocates per tick once connected.
#pragma once
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "devices/device.hpp"
#include "devices/device_mapping.hpp"
#include "devices/haply/haply_messages.hpp"
#include "common/triple_buffer.hpp"

namespace hs {

struct HaplySettings {
    /// Where the cursor's position at start() lands in the document, the travel scale, the
    /// session's force unit. Haply's frame (x right, y away from the user, z up) is the
    /// document's seen from the front.
    DeviceMapping mapping;
    std::string host = "127.0.0.1";
    int port = 10001;
    std::string deviceId;       ///< "": the first Inverse3 the service lists
    double maxForce = 0;        ///< N; 0: the table's rating (device_limits.hpp)
    double rateHz = kDefaultHapticRate;       ///< the haptic loop's rate the passivity bound is taken at
    double connectTimeout = 3;  ///< s to connect and receive the inventory
    double staleAfter = 0.1;    ///< s without a state update before the device counts as lost
    void validate() const;
};

class HaplyDevice final : public Device {
public:
    explicit HaplyDevice(HaplySettings settings);
    ~HaplyDevice() override;
    std::string name() const override { return "inverse3"; }
    DeviceCaps caps() const override;
    /// Connects, reads the inventory, picks the device and takes its first state (std::runtime_error
    /// saying why not: no service, no Inverse3, the asked one missing, in use).
    void start() override;
    /// Zero force, then closes the link.
    void stop() override;
    bool sample(double t, DeviceSample& out) override;
    void setForce(const Vec3& force) override;
    std::string deviceId() const { return deviceId_; }
    std::uint64_t updates() const { return updates_.load(std::memory_order_relaxed); }
    /// State updates that could not be read (kept the last good state).
    std::uint64_t malformed() const { return malformed_.load(std::memory_order_relaxed); }

    /// The Inverse3s the service at host:port lists (std::runtime_error when it cannot be reached).
    static std::vector<haply::Inverse3Info> discover(const std::string& host, int port, double timeout = 2.0);

    struct Link;  // the libwebsockets side (haply_device.cpp)

private:
    void ioLoop();
    HaplySettings settings_;
    std::unique_ptr<Link> link_;
    std::thread io_;
    std::string deviceId_;
    double forceLimit_ = 0;
    Vec3 centre_ = Vec3::Zero();  // m: the cursor at start(), mapped to the mapping's origin
    TripleBuffer<haply::State> state_{haply::State{}};
    std::atomic<double> force_[3] = {0.0, 0.0, 0.0};
    std::atomic<bool> lost_{false};
    std::atomic<std::uint64_t> updates_{0}, malformed_{0};
    std::uint64_t seen_ = 0;
    std::chrono::steady_clock::time_point lastUpdate_{};
    friend struct Link;
};

}  // namespace hs
