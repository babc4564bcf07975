#include "devices/hid/recorded_transport.hpp"

#include <algorithm>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace hs {

namespace {
std::vector<std::uint8_t> hexBytes(std::istringstream& in, std::size_t count, int line) {
    std::vector<std::uint8_t> out;
    std::string tok;
    while (in >> tok) {
        unsigned long v = 0;
        try {
            std::size_t used = 0;
            v = std::stoul(tok, &used, 16);
            if (used != tok.size() || v > 255) throw std::invalid_argument("");
        } catch (const std::exception&) {
            throw std::invalid_argument("recording: line " + std::to_string(line) + ": '" + tok + "' is not a hex byte");
        }
        out.push_back(static_cast<std::uint8_t>(v));
    }
    if (out.size() != count)
        throw std::invalid_argument("recording: line " + std::to_string(line) + ": expected " + std::to_string(count) +
                                    " bytes, got " + std::to_string(out.size()));
    return out;
}
}  // namespace

HidRecording parseHidRecording(const std::string& text) {
    HidRecording rec;
    std::istringstream lines(text);
    std::string line;
    int number = 0;
    while (std::getline(lines, line)) {
        ++number;
        if (line.empty() || line[0] == '#') continue;
        if (line.size() < 2 || line[1] != ':') throw std::invalid_argument("recording: line " + std::to_string(number) + ": expected 'X: ...'");
        std::istringstream in(line.substr(2));
        switch (line[0]) {
            case 'N': {
                std::string name;
                std::getline(in >> std::ws, name);
                rec.info.name = name;
                break;
            }
            case 'I': {
                unsigned bus = 0, vid = 0, pid = 0;
                if (!(in >> std::hex >> bus >> vid >> pid) || vid > 0xffff || pid > 0xffff)
                    throw std::invalid_argument("recording: line " + std::to_string(number) + ": expected 'I: bus vid pid' in hex");
                rec.info.vendorId = static_cast<std::uint16_t>(vid);
                rec.info.productId = static_cast<std::uint16_t>(pid);
                break;
            }
            case 'R': {
                std::size_t len = 0;
                if (!(in >> len) || len > 65536) throw std::invalid_argument("recording: line " + std::to_string(number) + ": bad descriptor length");
                rec.descriptor = hexBytes(in, len, number);
                break;
            }
            case 'E': {
                std::string stamp;
                std::size_t len = 0;
                if (!(in >> stamp >> len) || len > 4096) throw std::invalid_argument("recording: line " + std::to_string(number) + ": expected 'E: sec.usec len bytes'");
                RecordedEvent e;
                const auto dot = stamp.find('.');
                try {
                    e.time = std::stod(stamp.substr(0, dot)) + (dot == std::string::npos ? 0.0 : std::stod("0" + stamp.substr(dot)));
                } catch (const std::exception&) {
                    throw std::invalid_argument("recording: line " + std::to_string(number) + ": bad timestamp '" + stamp + "'");
                }
                e.bytes = hexBytes(in, len, number);
                if (!rec.events.empty() && e.time < rec.events.back().time)
                    throw std::invalid_argument("recording: line " + std::to_string(number) + ": timestamps go back in time");
                rec.events.push_back(std::move(e));
                break;
            }
            default:
                break;  // other hid-recorder lines (e.g. 'D:', 'B:') carry nothing we need
        }
    }
    return rec;
}

RecordedTransport::RecordedTransport(HidRecording recording, bool paced, bool lossAtEnd)
    : rec_(std::move(recording)), paced_(paced), lossAtEnd_(lossAtEnd) {}

int RecordedTransport::read(std::uint8_t* buf, std::size_t size, int timeoutMs) {
    if (!begun_) {
        begun_ = true;
        start_ = std::chrono::steady_clock::now();
    }
    if (next_ >= rec_.events.size()) {
        if (lossAtEnd_) return -1;
        if (timeoutMs > 0) std::this_thread::sleep_for(std::chrono::milliseconds(timeoutMs));
        return 0;
    }
    const RecordedEvent& e = rec_.events[next_];
    if (paced_) {
        const double base = rec_.events.front().time;
        const auto due = start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(e.time - base));
        const auto now = std::chrono::steady_clock::now();
        if (due > now) {
            if (timeoutMs == 0) return 0;
            const auto limit = now + std::chrono::milliseconds(timeoutMs < 0 ? 1000000 : timeoutMs);
            std::this_thread::sleep_until(std::min(due, limit));
            if (due > limit) return 0;
        }
    }
    ++next_;
    const std::size_t n = std::min(size, e.bytes.size());  // like hidraw: truncated to the buffer
    if (n) std::memcpy(buf, e.bytes.data(), n);
    return static_cast<int>(n);
}

int RecordedTransport::write(const std::uint8_t* buf, std::size_t size) {
    std::lock_guard<std::mutex> lock(writeMutex_);
    written_.emplace_back(buf, buf + size);
    return static_cast<int>(size);
}

int RecordedTransport::sendFeature(const std::uint8_t* buf, std::size_t size) { return write(buf, size); }

int RecordedTransport::getFeature(std::uint8_t*, std::size_t) { return -1; }

std::vector<std::vector<std::uint8_t>> RecordedTransport::written() const {
    std::lock_guard<std::mutex> lock(writeMutex_);
    return written_;
}

bool RecordedTransport::finished() const { return next_ >= rec_.events.size(); }

}  // namespace hs
