// A transport that replays a hid-recorder text file (hid-tools' format: `N: name`, `I: bus vid pid`,
// `R: len bytes` the report descriptor, `E: sec.usec len bytes` one input report), either paced by
// its timestamps or as fast as it is read, and logs everything written to it.
#pragma once
#include <chrono>
#include <mutex>
#include <string>
#include <vector>

#include "devices/hid/hid_transport.hpp"

namespace hs {

struct RecordedEvent {
    double time = 0;
    std::vector<std::uint8_t> bytes;
};

struct HidRecording {
    HidInfo info;
    std::vector<std::uint8_t> descriptor;
    std::vector<RecordedEvent> events;
};

/// Parses the text; throws std::invalid_argument naming the line for malformed input.
HidRecording parseHidRecording(const std::string& text);

class RecordedTransport final : public HidTransport {
public:
    /// paced: events arrive at their recorded times after the first read; else back to back.
    /// lossAtEnd: after the last event read() reports the device gone (-1) instead of idling.
    RecordedTransport(HidRecording recording, bool paced, bool lossAtEnd = false);
    HidInfo info() const override { return rec_.info; }
    int read(std::uint8_t* buf, std::size_t size, int timeoutMs) override;
    int write(const std::uint8_t* buf, std::size_t size) override;
    int sendFeature(const std::uint8_t* buf, std::size_t size) override;
    int getFeature(std::uint8_t* buf, std::size_t size) override;
    std::vector<std::uint8_t> reportDescriptor() override { return rec_.descriptor; }
    /// Everything written (outputs and features), oldest first.
    std::vector<std::vector<std::uint8_t>> written() const;
    bool finished() const;

private:
    HidRecording rec_;
    bool paced_, lossAtEnd_;
    std::size_t next_ = 0;
    bool begun_ = false;
    std::chrono::steady_clock::time_point start_;
    mutable std::mutex writeMutex_;
    std::vector<std::vector<std::uint8_t>> written_;
};

}  // namespace hs
