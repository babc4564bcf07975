// 3Dconnexion SpaceMouse family over HID (input only): the known devices, a report parser for both
// layouts (split: report 1 translation + report 2 rotation, 3 x int16 each; combined: report 1 with
// all six axes in 13 bytes), buttons (report 3, and 0x1c/0x1d on the Enterprise), one explicit
// mapping from the HID frame to FreeCAD's, and a Device in rate or position control.
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>
#include <vector>

#include "devices/device.hpp"
#include "devices/hid/hid_transport.hpp"
#include "common/triple_buffer.hpp"

namespace hs {

struct SpaceMouseModel {
    std::uint16_t vendorId, productId;
    const char* name;
};
/// Every known SpaceMouse vendor/product id (0x046d Logitech era, 0x256f 3Dconnexion).
const std::vector<SpaceMouseModel>& spaceMouseModels();
const SpaceMouseModel* findSpaceMouse(std::uint16_t vendorId, std::uint16_t productId);

/// Raw HID axes (x, y, z, rx, ry, rz as the device reports them) and buttons.
struct SpaceMouseState {
    std::int16_t axes[6] = {0, 0, 0, 0, 0, 0};
    std::uint32_t buttons = 0;
    std::uint64_t reports = 0, malformed = 0, unknown = 0, ignored = 0;
    bool combinedLayout = false;
};

/// Parses input reports (ID byte first). Malformed (short, empty) and unknown reports are counted
/// and ignored; nothing here can read past the buffer.
class SpaceMouseParser {
public:
    /// Returns true when the report changed axes or buttons.
    bool feed(const std::uint8_t* report, std::size_t length);
    const SpaceMouseState& state() const { return state_; }

private:
    SpaceMouseState state_;
    std::uint32_t reportButtons_ = 0, enterpriseButtons_ = 0;
};

/// HID frame (+x right, +y toward the user, +z down, rotations right-handed about those) to
/// FreeCAD's (+x right, +y away from the user, +z up): a half turn about x, so
/// (x, y, z) -> (x, -y, -z) for translations and rotations alike. Scaled so full deflection is 1.
void hidToFreeCAD(const std::int16_t axes[6], double fullScale, double out[6]);

struct SpaceMouseSettings {
    enum class Mode { Rate, Position } mode = Mode::Rate;
    double translationScale = 100.0;  ///< rate: mm/s at full deflection; position: mm at full deflection
    double rotationScale = 1.5;       ///< rate: rad/s at full deflection; position: rad at full deflection
    double deadZone = 0.05;           ///< fraction of full deflection ignored around the centre
    double fullScale = 350.0;         ///< raw value of full deflection (real units exceed it: clamped)
    Vec3 origin = Vec3::Zero();       ///< cursor start (rate) or centre (position), mm
};

/// A SpaceMouse on a transport: an I/O thread drains reports (a 64-byte buffer, timeout reads) and
/// publishes the state; sample() integrates it (rate) or maps it (position) without blocking.
class SpaceMouseDevice final : public Device {
public:
    SpaceMouseDevice(std::unique_ptr<HidTransport> transport, SpaceMouseSettings settings);
    ~SpaceMouseDevice() override;
    std::string name() const override;
    DeviceCaps caps() const override { return {6, false, 62.5, 0, 0}; }
    void start() override;
    void stop() override;
    bool sample(double t, DeviceSample& out) override;
    /// Latest raw state (counts of reports, malformed and unknown ones), from any thread.
    SpaceMouseState state();
    /// True once the transport reported the device gone.
    bool lost() const { return lost_.load(std::memory_order_acquire); }

private:
    void ioLoop();
    std::unique_ptr<HidTransport> transport_;
    SpaceMouseSettings settings_;
    HidInfo info_;
    std::thread io_;
    std::atomic<bool> running_{false}, lost_{false};
    TripleBuffer<SpaceMouseState> published_;
    SpaceMouseState reader_;
    // haptic-thread integration state (rate mode)
    Vec3 position_;
    Eigen::Quaterniond orientation_ = Eigen::Quaterniond::Identity();
    double lastT_ = -1;
};

}  // namespace hs
