#include "devices/hid/hidapi_transport.hpp"

#include <hidapi/hidapi.h>

#include <cstdio>
#include <cwchar>
#include <stdexcept>

namespace hs {

namespace {
std::string narrow(const wchar_t* w) {
    std::string out;
    if (!w) return out;
    for (; *w; ++w) out.push_back(*w < 128 ? static_cast<char>(*w) : '?');
    return out;
}

// hid_init is idempotent; hidapi keeps its own state.
bool initialised() { return hid_init() == 0; }
}  // namespace

std::vector<HidInfo> enumerateHid() {
    std::vector<HidInfo> out;
    if (!initialised()) return out;
    hid_device_info* list = hid_enumerate(0, 0);
    for (hid_device_info* d = list; d; d = d->next) {
        HidInfo i;
        i.vendorId = d->vendor_id;
        i.productId = d->product_id;
        i.path = d->path ? d->path : "";
        i.name = narrow(d->product_string);
        i.usagePage = d->usage_page;
        i.usage = d->usage;
        out.push_back(i);
    }
    hid_free_enumeration(list);
    return out;
}

void HidapiTransport::Closer::operator()(hid_device_* d) const {
    if (d) hid_close(d);
}

HidapiTransport::HidapiTransport(const std::string& path) {
    if (!initialised()) throw std::runtime_error("hidapi: hid_init failed");
    device_.reset(hid_open_path(path.c_str()));
    if (!device_) throw std::runtime_error("path: cannot open HID device " + path + " (permissions? see the udev rules)");
    info_.path = path;
    for (const HidInfo& i : enumerateHid())
        if (i.path == path) info_ = i;
}

HidapiTransport::~HidapiTransport() = default;

int HidapiTransport::read(std::uint8_t* buf, std::size_t size, int timeoutMs) {
    return hid_read_timeout(device_.get(), buf, size, timeoutMs);
}
int HidapiTransport::write(const std::uint8_t* buf, std::size_t size) { return hid_write(device_.get(), buf, size); }
int HidapiTransport::sendFeature(const std::uint8_t* buf, std::size_t size) {
    return hid_send_feature_report(device_.get(), buf, size);
}
int HidapiTransport::getFeature(std::uint8_t* buf, std::size_t size) {
    return hid_get_feature_report(device_.get(), buf, size);
}

std::vector<std::uint8_t> HidapiTransport::reportDescriptor() {
#if defined(HID_API_VERSION) && HID_API_VERSION >= HID_API_MAKE_VERSION(0, 14, 0)
    std::vector<std::uint8_t> buf(4096);
    const int n = hid_get_report_descriptor(device_.get(), buf.data(), buf.size());
    if (n < 0) throw std::runtime_error("hidapi: cannot read the report descriptor");
    buf.resize(static_cast<std::size_t>(n));
    return buf;
#else
    // hidapi < 0.14 (Debian 12 ships 0.13): read it from sysfs, next to the hidraw node.
    const std::string node = info_.path.substr(info_.path.find_last_of('/') + 1);
    const std::string sysfs = "/sys/class/hidraw/" + node + "/device/report_descriptor";
    std::FILE* f = std::fopen(sysfs.c_str(), "rb");
    if (!f) throw std::runtime_error("hidapi: cannot read " + sysfs);
    std::vector<std::uint8_t> buf(4096);
    const std::size_t n = std::fread(buf.data(), 1, buf.size(), f);
    std::fclose(f);
    buf.resize(n);
    return buf;
#endif
}

}  // namespace hs
