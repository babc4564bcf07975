// Byte-level access to one HID device, behind one interface so the drivers run the same against
// hidapi (hidraw), a recorded fixture or an emulator. Report buffers start with the report ID.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace hs {

struct HidInfo {
    std::uint16_t vendorId = 0, productId = 0;
    std::string name, path;
    std::uint16_t usagePage = 0, usage = 0;
};

class HidTransport {
public:
    virtual ~HidTransport() = default;
    virtual HidInfo info() const = 0;
    /// Reads one input report into buf (ID first). Returns its length, 0 on timeout, -1 when the
    /// device is gone. timeoutMs: -1 blocks, 0 polls.
    virtual int read(std::uint8_t* buf, std::size_t size, int timeoutMs) = 0;
    /// Writes an output report (buf[0] = report ID). Returns bytes written or -1.
    virtual int write(const std::uint8_t* buf, std::size_t size) = 0;
    virtual int sendFeature(const std::uint8_t* buf, std::size_t size) = 0;
    /// Reads a feature report: buf[0] holds the wanted ID on entry. Returns its length or -1.
    virtual int getFeature(std::uint8_t* buf, std::size_t size) = 0;
    virtual std::vector<std::uint8_t> reportDescriptor() = 0;
};

}  // namespace hs
