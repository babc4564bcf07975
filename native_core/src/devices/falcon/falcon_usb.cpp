#include "devices/falcon/falcon_usb.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "devices/falcon/falcon_frames.hpp"

namespace hs::falcon {

namespace {
// FTDI vendor requests (bmRequestType 0x40, the FTDI's SIO commands as libftdi names them)
constexpr std::uint8_t kReset = 0, kModemCtrl = 1, kFlowCtrl = 2, kBaudRate = 3, kData = 4, kLatency = 9;
constexpr std::uint16_t kPurgeRx = 1, kPurgeTx = 2;
constexpr std::uint16_t kDtrHigh = 0x0101, kDtrLow = 0x0100, kRtsLow = 0x0200;
// baud-rate divisors: 9600 for the loader's handshake, 140 kBd for the image, ~1.46 MBd running
constexpr std::uint16_t kBaud9600 = 0x4138, kBaudLoader = 0x15, kBaudRunning = 0x2;
constexpr unsigned char kOut = 0x02, kIn = 0x81;
constexpr std::size_t kPacket = 64, kStatusBytes = 2, kChunk = 62;

bool gone(int rc) { return rc == usb::kNoDevice || rc == usb::kIo || rc == usb::kPipe; }
}  // namespace

std::vector<usb::Library::Found> attachedFalcons(const usb::Library& usb) { return usb.find(kUsbVendor, kUsbProduct); }

UsbTransport::UsbTransport(std::shared_ptr<usb::Library> usbLib, int index) : usb_(std::move(usbLib)) {
    if (!usb_) throw std::invalid_argument("usb: none given");
    const usb::Api& a = usb_->api();
    usb::Device** list = nullptr;
    const long n = a.getDeviceList(usb_->context(), &list);
    if (n < 0) throw std::runtime_error("Falcon: cannot list the USB devices (" + usb_->errorName(static_cast<int>(n)) + ")");
    int seen = 0, rc = usb::kNotFound;
    for (long i = 0; i < n; ++i) {
        usb::DeviceDescriptor d{};
        if (a.getDeviceDescriptor(list[i], &d) < 0 || d.idVendor != kUsbVendor || d.idProduct != kUsbProduct) continue;
        if (seen++ == index) {
            rc = a.open(list[i], &handle_);
            break;
        }
    }
    a.freeDeviceList(list, 1);
    if (rc == usb::kNotFound)
        throw std::runtime_error("Falcon: none attached" + (index > 0 ? " at index " + std::to_string(index) : std::string()) +
                                 " (USB 0403:cb48)");
    if (rc == usb::kAccess)
        throw std::runtime_error("Falcon: no permission to open it: install the udev rule (sudo make install-udev) and plug it in again");
    if (rc != usb::kSuccess) throw std::runtime_error("Falcon: cannot open it (" + usb_->errorName(rc) + ")");
    if (a.kernelDriverActive(handle_, 0) == 1) a.detachKernelDriver(handle_, 0);  // ftdi_sio, if it bound
    rc = a.claimInterface(handle_, 0);
    if (rc != usb::kSuccess) {
        a.close(handle_);
        handle_ = nullptr;
        throw std::runtime_error(rc == usb::kBusy ? "Falcon: in use by another program" : "Falcon: cannot claim it (" + usb_->errorName(rc) + ")");
    }
    setRunningMode();
}

UsbTransport::~UsbTransport() {
    if (!handle_) return;
    usb_->api().releaseInterface(handle_, 0);
    usb_->api().close(handle_);
}

void UsbTransport::control(std::uint8_t request, std::uint16_t value, const char* what) {
    const int rc = usb_->api().controlTransfer(handle_, 0x40, request, value, 0, nullptr, 0, 1000);
    if (rc < 0) throw std::runtime_error(std::string("Falcon: ") + what + " failed (" + usb_->errorName(rc) + ")");
}

void UsbTransport::setRunningMode() {
    control(kLatency, 1, "setting the latency timer");
    control(kBaudRate, kBaudRunning, "setting the baud rate");
    control(kReset, kPurgeRx, "purging");
    control(kReset, kPurgeTx, "purging");
    pendingLen_ = 0;
}

void UsbTransport::bulkOut(const std::uint8_t* data, int n, const char* what) {
    int done = 0;
    const int rc = usb_->api().bulkTransfer(handle_, kOut, const_cast<std::uint8_t*>(data), n, &done, 1000);
    if (rc < 0 || done != n) throw std::runtime_error(std::string("Falcon: ") + what + ": write failed (" + usb_->errorName(rc) + ")");
}

long UsbTransport::bulkIn(std::uint8_t* data, std::size_t capacity, unsigned int timeoutMs) {
    if (pendingLen_ == 0) {
        int got = 0;
        // (libusb's own transfer bookkeeping allocates inside libusb; nothing here does)
        const int rc = usb_->api().bulkTransfer(handle_, kIn, raw_.data(), static_cast<int>(raw_.size()), &got, std::max(1u, timeoutMs));
        if (rc < 0 && gone(rc)) return -1;
        for (std::size_t at = 0; at < static_cast<std::size_t>(std::max(got, 0)); at += kPacket) {
            const std::size_t end = std::min(at + kPacket, static_cast<std::size_t>(got));
            if (end <= at + kStatusBytes) continue;  // a status-only packet: nothing arrived
            const std::size_t n = std::min(end - at - kStatusBytes, pending_.size() - pendingLen_);
            std::memcpy(pending_.data() + pendingLen_, raw_.data() + at + kStatusBytes, n);
            pendingLen_ += n;
        }
    }
    const std::size_t n = std::min(capacity, pendingLen_);
    std::memcpy(data, pending_.data(), n);
    std::memmove(pending_.data(), pending_.data() + n, pendingLen_ - n);
    pendingLen_ -= n;
    return static_cast<long>(n);
}

bool UsbTransport::write(const std::uint8_t* data, std::size_t n) {
    if (!handle_) return false;
    int done = 0;
    const int rc = usb_->api().bulkTransfer(handle_, kOut, const_cast<std::uint8_t*>(data), static_cast<int>(n), &done, 100);
    return rc == usb::kSuccess && done == static_cast<int>(n);
}

long UsbTransport::read(std::uint8_t* data, std::size_t capacity, double timeout) {
    if (!handle_) return -1;
    return bulkIn(data, capacity, static_cast<unsigned int>(std::ceil(std::max(0.0, timeout) * 1000)));
}

bool UsbTransport::firmwareRunning() {
    const Frame probe = encodeCommand(Command{});
    FrameReader reader;
    std::array<std::uint8_t, 64> buf{};
    for (int attempt = 0; attempt < 10; ++attempt) {
        if (!write(probe.data(), probe.size())) return false;
        for (int k = 0; k < 20; ++k) {
            const long n = read(buf.data(), buf.size(), 0.001);
            if (n < 0) return false;
            if (n > 0 && reader.feed(buf.data(), static_cast<std::size_t>(n)) > 0) return true;
        }
    }
    return false;
}

void UsbTransport::expect(const std::uint8_t* bytes, std::size_t n, const char* what, bool skipZeros) {
    std::array<std::uint8_t, 128> got{};
    std::size_t have = 0;
    for (int tries = 0; have < n && tries < 200; ++tries) {
        const long k = bulkIn(got.data() + have, std::min(n - have, got.size() - have), 5);
        if (k < 0) throw std::runtime_error(std::string("Falcon: unplugged during ") + what);
        have += static_cast<std::size_t>(k);
        while (skipZeros && have > 0 && got[0] == 0) {  // (some hosts see a 0 before the loader's answer)
            std::memmove(got.data(), got.data() + 1, --have);
        }
    }
    if (have < n) throw std::runtime_error(std::string("Falcon: no answer to ") + what);
    if (std::memcmp(got.data(), bytes, n) != 0) throw std::runtime_error(std::string("Falcon: wrong answer to ") + what);
}

void UsbTransport::loadFirmware(const std::vector<std::uint8_t>& image) {
    if (image.empty()) throw std::invalid_argument("firmware: the image is empty");
    control(kReset, kPurgeRx, "purging");
    control(kReset, kPurgeTx, "purging");
    control(kLatency, 16, "setting the latency timer");  // 1 ms makes the loader's handshake fail
    control(kBaudRate, kBaud9600, "setting the baud rate");
    control(kData, 8, "setting 8N1");
    control(kFlowCtrl, 0, "turning off flow control");
    control(kModemCtrl, kRtsLow, "setting RTS");
    control(kModemCtrl, kDtrLow, "setting DTR");
    control(kModemCtrl, kDtrHigh, "setting DTR");  // DTR low to high: the loader starts
    pendingLen_ = 0;
    const std::uint8_t hello[3] = {0x0a, 0x43, 0x0d}, answer[4] = {0x0a, 0x44, 0x2c, 0x0d};
    bool greeted = false;
    for (int attempt = 0; attempt < 10 && !greeted; ++attempt) {
        bulkOut(hello, 3, "the loader's handshake");
        try {
            expect(answer, 4, "the loader's handshake", true);
            greeted = true;
        } catch (const std::runtime_error&) {
            pendingLen_ = 0;
        }
    }
    if (!greeted) throw std::runtime_error("Falcon: the firmware loader did not answer its handshake (unplug the Falcon's power and USB, plug them in again)");
    control(kModemCtrl, kDtrLow, "setting DTR");
    control(kBaudRate, kBaudLoader, "setting the loader's baud rate");
    const std::uint8_t a = 0x41;
    bulkOut(&a, 1, "the loader's start");
    expect(&a, 1, "the loader's start");
    for (std::size_t at = 0; at < image.size(); at += kChunk) {
        const std::size_t n = std::min(kChunk, image.size() - at);
        bulkOut(image.data() + at, static_cast<int>(n), "the firmware image");
        expect(image.data() + at, n, "the firmware image (each chunk comes back)");
    }
    setRunningMode();
}

void UsbTransport::loadFirmwareFile(const std::string& path, int attempts) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw std::runtime_error("firmware: cannot read " + path);
    const std::vector<std::uint8_t> image((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    if (image.empty()) throw std::runtime_error("firmware: " + path + " is empty");
    std::string why;
    for (int k = 0; k < attempts; ++k) {
        try {
            loadFirmware(image);
            if (firmwareRunning()) return;
            why = "the firmware did not start (is " + path + " the Falcon's firmware?)";
        } catch (const std::runtime_error& e) {
            why = e.what();
        }
    }
    throw std::runtime_error(why + " (after " + std::to_string(attempts) + " attempts)");
}

}  // namespace hs::falcon

namespace hs::falcon {

std::shared_ptr<UsbTransport> openFalconUsb(std::shared_ptr<usb::Library> usbLib, int index, const std::string& firmwarePath) {
    auto t = std::make_shared<UsbTransport>(std::move(usbLib), index);
    if (t->firmwareRunning()) return t;
    if (firmwarePath.empty())
        throw std::runtime_error("Falcon: its firmware is not loaded (it must be, after each power-up): give the firmware "
                                 "file, Novint's image (see the README, \"Force devices\")");
    t->loadFirmwareFile(firmwarePath);
    return t;
}

}  // namespace hs::falcon
