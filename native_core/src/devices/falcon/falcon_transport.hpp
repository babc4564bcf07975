// The byte link to a Novint Falcon: an FTDI serial bridge on USB. The driver writes one command
// frame and reads one status frame per I/O cycle (falcon_frames.hpp); the real link is libusb
// with the FTDI chip in the mode the loaded firmware runs at, and the tests use an emulator.
#pragma once
#include <cstddef>
#include <cstdint>

namespace hs::falcon {

class Transport {
public:
    virtual ~Transport() = default;
    /// Sends bytes; false when the device is gone.
    virtual bool write(const std::uint8_t* data, std::size_t n) = 0;
    /// Whatever has arrived (up to `capacity`), waiting at most `timeout` seconds for the first
    /// byte; 0 on timeout, -1 when the device is gone. Runs on the haptic thread: no allocation.
    virtual long read(std::uint8_t* data, std::size_t capacity, double timeout) = 0;
};

}  // namespace hs::falcon
