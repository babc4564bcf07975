// A fake libusb-1.0 for the tests: the calls the Falcon's UsbTransport loads, over an FTDI bridge
// and the emulated Falcon (falcon_emulator.hpp) behind it. It keeps the FTDI's behaviour that
// matters: control requests set baud rate, DTR and latency; each IN packet starts with two modem
// status bytes; the Falcon's loader answers its handshake at 9600 Bd after DTR goes low to high,
// starts on 'A' at the loader's rate and echoes the image; the firmware runs when the image was
// the expected one and the running mode is set. fake_usb_* calls steer it.
#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <vector>

#include "../falcon_emulator.hpp"

namespace {
enum class Mode { Off, Handshake, AwaitA, Loading, Running };
struct Waypoint {
    double t, x, y, z;
    int buttons;
};

struct State {
    std::mutex lock;
    int devices = 1;
    bool denied = false, busy = false, claimed = false, open = false;
    bool firmware = false;  // running
    std::vector<std::uint8_t> expected, received;
    long corruptEchoAt = -1;
    std::uint16_t baud = 0;
    bool dtr = false;
    Mode mode = Mode::Off;
    std::vector<std::uint8_t> out;  // bytes the host has not read yet
    hs::falcon::Emulator falcon;
    std::array<Waypoint, 16> script{};
    std::size_t scriptLength = 0;
    long unplugAfter = -1;
};
State& state() {
    static State s;
    return s;
}
int deviceTag[4];  // the fake libusb_device pointers: their addresses
int handleTag;

hs::falcon::Vec3d handAt(double t) {
    const State& s = state();
    if (s.scriptLength == 0) return hs::falcon::Vec3d(0, 0, 0.11);
    std::size_t k = 0;
    while (k + 1 < s.scriptLength && s.script[k + 1].t <= t) ++k;
    const Waypoint& a = s.script[k];
    if (k + 1 >= s.scriptLength) return hs::falcon::Vec3d(a.x, a.y, a.z);
    const Waypoint& b = s.script[k + 1];
    const double u = (t - a.t) / (b.t - a.t);
    return hs::falcon::Vec3d(a.x + u * (b.x - a.x), a.y + u * (b.y - a.y), a.z + u * (b.z - a.z));
}
std::uint8_t buttonsAt(double t) {
    const State& s = state();
    std::size_t k = 0;
    while (k + 1 < s.scriptLength && s.script[k + 1].t <= t) ++k;
    return s.scriptLength ? static_cast<std::uint8_t>(s.script[k].buttons) : 0;
}
bool unplugged(const State& s) { return s.unplugAfter >= 0 && s.falcon.commands >= s.unplugAfter; }
}  // namespace

extern "C" {
struct libusb_device_descriptor {
    std::uint8_t bLength, bDescriptorType;
    std::uint16_t bcdUSB;
    std::uint8_t bDeviceClass, bDeviceSubClass, bDeviceProtocol, bMaxPacketSize0;
    std::uint16_t idVendor, idProduct, bcdDevice;
    std::uint8_t iManufacturer, iProduct, iSerialNumber, bNumConfigurations;
};

void fake_usb_reset(int firmwareRunning);
void fake_usb_script(const double* rows, int n);

// A process that cannot call fake_usb_* (FreeCAD in the GUI tests) names a script file instead:
// HS_FAKE_FALCON_SCRIPT, rows of "t x y z buttons"; the Falcon then runs its firmware.
int libusb_init(void** ctx) {
    *ctx = &handleTag;
    if (const char* path = std::getenv("HS_FAKE_FALCON_SCRIPT")) {
        std::vector<double> rows;
        if (std::FILE* f = std::fopen(path, "r")) {
            double v;
            while (std::fscanf(f, "%lf", &v) == 1) rows.push_back(v);
            std::fclose(f);
        }
        fake_usb_reset(1);
        fake_usb_script(rows.data(), static_cast<int>(rows.size() / 5));
    }
    return 0;
}
void libusb_exit(void*) {}
long libusb_get_device_list(void*, void*** list) {
    State& s = state();
    std::lock_guard<std::mutex> g(s.lock);
    static void* devices[6];
    devices[0] = &deviceTag[3];  // a device that is not a Falcon
    for (int i = 0; i < s.devices; ++i) devices[i + 1] = &deviceTag[i];
    devices[s.devices + 1] = nullptr;
    *list = devices;
    return s.devices + 1;
}
void libusb_free_device_list(void**, int) {}
int libusb_get_device_descriptor(void* dev, libusb_device_descriptor* d) {
    std::memset(d, 0, sizeof *d);
    d->bLength = 18;
    const bool falcon = dev != &deviceTag[3];
    d->idVendor = falcon ? 0x0403 : 0x046d;
    d->idProduct = falcon ? 0xcb48 : 0xc52b;
    return 0;
}
std::uint8_t libusb_get_bus_number(void*) { return 3; }
std::uint8_t libusb_get_device_address(void* dev) { return static_cast<std::uint8_t>(10 + (static_cast<int*>(dev) - deviceTag)); }
int libusb_open(void*, void** handle) {
    State& s = state();
    std::lock_guard<std::mutex> g(s.lock);
    if (s.denied) return -3;  // LIBUSB_ERROR_ACCESS
    s.open = true;
    *handle = &handleTag;
    return 0;
}
void libusb_close(void*) {
    std::lock_guard<std::mutex> g(state().lock);
    state().open = state().claimed = false;
}
int libusb_kernel_driver_active(void*, int) { return 0; }
int libusb_detach_kernel_driver(void*, int) { return 0; }
int libusb_claim_interface(void*, int) {
    State& s = state();
    std::lock_guard<std::mutex> g(s.lock);
    if (s.busy) return -6;  // LIBUSB_ERROR_BUSY
    s.claimed = true;
    return 0;
}
int libusb_release_interface(void*, int) {
    std::lock_guard<std::mutex> g(state().lock);
    state().claimed = false;
    return 0;
}
int libusb_control_transfer(void*, std::uint8_t type, std::uint8_t request, std::uint16_t value, std::uint16_t, unsigned char*,
                            std::uint16_t, unsigned int) {
    State& s = state();
    std::lock_guard<std::mutex> g(s.lock);
    if (unplugged(s)) return -4;
    if (type != 0x40) return -9;
    if (request == 0 && value == 1) s.out.clear();  // purge RX
    if (request == 3) {
        s.baud = value;
        if (value == 0x2) {  // the running mode: the firmware runs if the image came whole
            if (s.mode == Mode::Loading) s.firmware = !s.expected.empty() && s.received == s.expected;
            s.mode = Mode::Running;
        } else if (value == 0x15 && s.mode == Mode::Handshake && !s.dtr) {
            s.mode = Mode::AwaitA;
        }
    }
    if (request == 1 && (value & 0x0100)) {  // DTR
        const bool high = value & 1;
        if (high && !s.dtr && s.baud == 0x4138) {  // low to high at 9600: the loader restarts
            s.mode = Mode::Handshake;
            s.firmware = false;
            s.received.clear();
        }
        s.dtr = high;
    }
    return 0;
}
int libusb_bulk_transfer(void*, unsigned char endpoint, unsigned char* data, int length, int* transferred, unsigned int) {
    State& s = state();
    std::lock_guard<std::mutex> g(s.lock);
    *transferred = 0;
    if (unplugged(s)) return -4;  // LIBUSB_ERROR_NO_DEVICE
    if (endpoint == 0x02) {  // OUT
        const std::uint8_t* in = data;
        switch (s.mode) {
            case Mode::Handshake:
                if (length == 3 && in[0] == 0x0a && in[1] == 0x43 && in[2] == 0x0d) s.out.insert(s.out.end(), {0x0a, 0x44, 0x2c, 0x0d});
                break;
            case Mode::AwaitA:
                if (length == 1 && in[0] == 0x41) {
                    s.out.push_back(0x41);
                    s.mode = Mode::Loading;
                }
                break;
            case Mode::Loading:
                for (int i = 0; i < length; ++i) {
                    s.received.push_back(in[i]);
                    const bool corrupt = s.corruptEchoAt >= 0 && static_cast<long>(s.received.size()) == s.corruptEchoAt + 1;
                    s.out.push_back(corrupt ? static_cast<std::uint8_t>(in[i] ^ 0xff) : in[i]);
                }
                break;
            case Mode::Running:
                if (s.firmware) {
                    s.falcon.write(in, static_cast<std::size_t>(length));
                    std::array<std::uint8_t, 256> reply{};
                    const long n = s.falcon.read(reply.data(), reply.size(), 0);
                    if (n > 0) s.out.insert(s.out.end(), reply.begin(), reply.begin() + n);
                }
                break;
            case Mode::Off:
                break;
        }
        *transferred = length;
        return 0;
    }
    // IN: packets of 64 bytes, each two modem-status bytes and up to 62 of data
    int at = 0;
    std::size_t taken = 0;
    do {
        if (at + 2 > length) break;
        data[at++] = 0x31;
        data[at++] = 0x60;
        const std::size_t n = std::min({s.out.size() - taken, std::size_t{62}, static_cast<std::size_t>(length - at)});
        if (n) std::memcpy(data + at, s.out.data() + taken, n);
        at += static_cast<int>(n);
        taken += n;
    } while (taken < s.out.size());
    s.out.erase(s.out.begin(), s.out.begin() + static_cast<long>(taken));
    *transferred = at;
    return 0;
}
const char* libusb_error_name(int code) {
    switch (code) {
        case -3: return "LIBUSB_ERROR_ACCESS";
        case -4: return "LIBUSB_ERROR_NO_DEVICE";
        case -6: return "LIBUSB_ERROR_BUSY";
        default: return "LIBUSB_ERROR_OTHER";
    }
}

// --- the test's handles ---
void fake_usb_reset(int firmwareRunning) {
    State& s = state();
    std::lock_guard<std::mutex> g(s.lock);
    s.devices = 1;
    s.denied = s.busy = s.claimed = s.open = false;
    s.firmware = firmwareRunning != 0;
    s.expected.clear();
    s.received.clear();
    s.corruptEchoAt = -1;
    s.baud = 0;
    s.dtr = false;
    s.mode = s.firmware ? Mode::Running : Mode::Off;
    s.out.clear();
    s.falcon = hs::falcon::Emulator();
    s.falcon.homingFrames = 5;
    s.falcon.hand = handAt;
    s.falcon.buttons = buttonsAt;
    s.scriptLength = 0;
    s.unplugAfter = -1;
}
void fake_usb_devices(int n) {
    std::lock_guard<std::mutex> g(state().lock);
    state().devices = std::clamp(n, 0, 3);
}
void fake_usb_denied(int denied) {
    std::lock_guard<std::mutex> g(state().lock);
    state().denied = denied != 0;
}
void fake_usb_busy(int busy) {
    std::lock_guard<std::mutex> g(state().lock);
    state().busy = busy != 0;
}
void fake_usb_expected_firmware(const std::uint8_t* image, long n) {
    std::lock_guard<std::mutex> g(state().lock);
    state().expected.assign(image, image + n);
}
void fake_usb_corrupt_echo_at(long at) {
    std::lock_guard<std::mutex> g(state().lock);
    state().corruptEchoAt = at;
}
void fake_usb_unplug_after(long commands) {
    std::lock_guard<std::mutex> g(state().lock);
    state().unplugAfter = commands;
}
void fake_usb_script(const double* rows, int n) {  // rows of (t, x, y, z, buttons), the Falcon's frame (m)
    State& s = state();
    std::lock_guard<std::mutex> g(s.lock);
    s.scriptLength = static_cast<std::size_t>(std::clamp(n, 0, static_cast<int>(s.script.size())));
    for (std::size_t k = 0; k < s.scriptLength; ++k) {
        const double* r = rows + 5 * k;
        s.script[k] = {r[0], r[1], r[2], r[3], static_cast<int>(r[4])};
    }
    if (s.scriptLength) s.falcon.tip = hs::falcon::Vec3d(s.script[0].x, s.script[0].y, s.script[0].z);
}
void fake_usb_observe(double* tipMm, double* largestForce, long* commands, int* claimed) {
    State& s = state();
    std::lock_guard<std::mutex> g(s.lock);
    for (int i = 0; i < 3; ++i) tipMm[i] = 1000 * s.falcon.tip[i];
    *largestForce = s.falcon.largestForce;
    *commands = s.falcon.commands;
    *claimed = s.claimed ? 1 : 0;
}
int fake_usb_firmware_running() {
    std::lock_guard<std::mutex> g(state().lock);
    return state().firmware ? 1 : 0;
}
}
