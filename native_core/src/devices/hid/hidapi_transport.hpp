// The real transport: hidapi's hidraw backend (Debian's libhidapi-hidraw), which shares the device
// with the kernel and spacenavd instead of detaching it as the libusb backend would.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "devices/hid/hid_transport.hpp"

struct hid_device_;

namespace hs {

/// Every HID interface hidapi sees (empty when none or when hidapi cannot initialise).
std::vector<HidInfo> enumerateHid();

class HidapiTransport final : public HidTransport {
public:
    /// Opens a device by its hidraw path; throws std::runtime_error with hidapi's reason.
    explicit HidapiTransport(const std::string& path);
    ~HidapiTransport() override;
    HidInfo info() const override { return info_; }
    int read(std::uint8_t* buf, std::size_t size, int timeoutMs) override;
    int write(const std::uint8_t* buf, std::size_t size) override;
    int sendFeature(const std::uint8_t* buf, std::size_t size) override;
    int getFeature(std::uint8_t* buf, std::size_t size) override;
    std::vector<std::uint8_t> reportDescriptor() override;

private:
    struct Closer {
        void operator()(hid_device_* d) const;
    };
    std::unique_ptr<hid_device_, Closer> device_;
    HidInfo info_;
};

}  // namespace hs
