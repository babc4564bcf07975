// The Falcon's USB link: an FTDI serial bridge (0403:cb48) driven through libusb. Two modes, as
// the Falcon needs them: the loader mode that takes Novint's firmware after each power-up (slow
// baud rate, a handshake, the image in 62-byte chunks each echoed back), and the running mode the
// firmware talks in (1 ms latency timer, fast baud rate) where the frames of falcon_frames.hpp go
// back and forth. Each IN packet of the FTDI starts with two modem-status bytes, stripped here.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "devices/falcon/falcon_transport.hpp"
#include "devices/falcon/libusb_api.hpp"

namespace hs::falcon {

constexpr std::uint16_t kUsbVendor = 0x0403, kUsbProduct = 0xcb48;

class UsbTransport final : public Transport {
public:
    /// Opens the `index`-th attached Falcon and puts it in the running mode; std::runtime_error
    /// saying why not (none attached, no permission, in use).
    UsbTransport(std::shared_ptr<usb::Library> usb, int index = 0);
    ~UsbTransport() override;
    UsbTransport(const UsbTransport&) = delete;
    UsbTransport& operator=(const UsbTransport&) = delete;

    bool write(const std::uint8_t* data, std::size_t n) override;
    long read(std::uint8_t* data, std::size_t capacity, double timeout) override;

    /// True when firmware answers: a command frame gets a status frame back within ~0.2 s.
    bool firmwareRunning();
    /// Loads a firmware image (std::runtime_error saying which step failed); the Falcon is in the
    /// running mode afterwards. libnifalcon's users report loads that fail now and then: the
    /// caller retries (loadFirmwareFile does, 3 times).
    void loadFirmware(const std::vector<std::uint8_t>& image);
    /// Reads the file (std::runtime_error if it cannot) and loads it, up to `attempts` times.
    void loadFirmwareFile(const std::string& path, int attempts = 3);
    void setRunningMode();

private:
    void control(std::uint8_t request, std::uint16_t value, const char* what);
    void bulkOut(const std::uint8_t* data, int n, const char* what);
    /// Bytes in (modem-status bytes stripped), waiting up to timeoutMs for the first; -1 if gone.
    long bulkIn(std::uint8_t* data, std::size_t capacity, unsigned int timeoutMs);
    /// Exactly n bytes in, or std::runtime_error naming `what`.
    void expect(const std::uint8_t* bytes, std::size_t n, const char* what, bool skipZeros = false);

    std::shared_ptr<usb::Library> usb_;
    usb::DeviceHandle* handle_ = nullptr;
    std::array<std::uint8_t, 512> raw_{};      // one bulk IN: up to 8 packets of 64
    std::array<std::uint8_t, 512> pending_{};  // payload not yet handed out
    std::size_t pendingLen_ = 0;
};

/// The `index`-th Falcon with its firmware running: loaded from `firmwarePath` when it is not yet
/// (std::runtime_error saying what to do when no file is given or the load fails).
std::shared_ptr<UsbTransport> openFalconUsb(std::shared_ptr<usb::Library> usb, int index, const std::string& firmwarePath);

/// The Falcons attached, each with whether it can be opened and why not.
std::vector<usb::Library::Found> attachedFalcons(const usb::Library& usb);

}  // namespace hs::falcon
