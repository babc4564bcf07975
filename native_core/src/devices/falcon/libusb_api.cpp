#include "devices/falcon/libusb_api.hpp"

#include <stdexcept>

namespace hs::usb {

Library::Library(SharedLibrary lib) : lib_(std::move(lib)) {
    const SharedLibrary& l = lib_;
    api_.init = l.function<decltype(api_.init)>("libusb_init");
    api_.exit = l.function<decltype(api_.exit)>("libusb_exit");
    api_.getDeviceList = l.function<decltype(api_.getDeviceList)>("libusb_get_device_list");
    api_.freeDeviceList = l.function<decltype(api_.freeDeviceList)>("libusb_free_device_list");
    api_.getDeviceDescriptor = l.function<decltype(api_.getDeviceDescriptor)>("libusb_get_device_descriptor");
    api_.getBusNumber = l.function<decltype(api_.getBusNumber)>("libusb_get_bus_number");
    api_.getDeviceAddress = l.function<decltype(api_.getDeviceAddress)>("libusb_get_device_address");
    api_.open = l.function<decltype(api_.open)>("libusb_open");
    api_.close = l.function<decltype(api_.close)>("libusb_close");
    api_.kernelDriverActive = l.function<decltype(api_.kernelDriverActive)>("libusb_kernel_driver_active");
    api_.detachKernelDriver = l.function<decltype(api_.detachKernelDriver)>("libusb_detach_kernel_driver");
    api_.claimInterface = l.function<decltype(api_.claimInterface)>("libusb_claim_interface");
    api_.releaseInterface = l.function<decltype(api_.releaseInterface)>("libusb_release_interface");
    api_.controlTransfer = l.function<decltype(api_.controlTransfer)>("libusb_control_transfer");
    api_.bulkTransfer = l.function<decltype(api_.bulkTransfer)>("libusb_bulk_transfer");
    api_.errorName = l.function<decltype(api_.errorName)>("libusb_error_name");
    const int rc = api_.init(&context_);
    if (rc < 0) throw std::runtime_error("libusb: cannot initialise (" + errorName(rc) + ")");
}

std::shared_ptr<Library> Library::load(const std::vector<std::string>& names) {
    SharedLibrary lib = SharedLibrary::open(!names.empty() ? names
                                            : kWindows ? std::vector<std::string>{"libusb-1.0.dll"}
                                                       : std::vector<std::string>{"libusb-1.0.so.0", "libusb-1.0.so"},
                                            kWindows ? "libusb-1.0 (libusb-1.0.dll from libusb.info, beside FreeCAD's bin folder)"
                                                     : "libusb-1.0 (Debian: apt install libusb-1.0-0)");
    return std::shared_ptr<Library>(new Library(std::move(lib)));
}

Library::~Library() {
    if (context_) api_.exit(context_);
}

std::string Library::errorName(int code) const {
    const char* n = api_.errorName(code);
    return n ? n : std::to_string(code);
}

std::vector<Library::Found> Library::find(std::uint16_t vendor, std::uint16_t product) const {
    std::vector<Found> out;
    Device** list = nullptr;
    const long n = api_.getDeviceList(context_, &list);
    if (n < 0) throw std::runtime_error("libusb: cannot list the USB devices (" + errorName(static_cast<int>(n)) + ")");
    for (long i = 0; i < n; ++i) {
        DeviceDescriptor d{};
        if (api_.getDeviceDescriptor(list[i], &d) < 0 || d.idVendor != vendor || d.idProduct != product) continue;
        Found f;
        f.bus = api_.getBusNumber(list[i]);
        f.address = api_.getDeviceAddress(list[i]);
        DeviceHandle* h = nullptr;
        const int rc = api_.open(list[i], &h);
        if (rc == kSuccess) {
            f.openable = true;
            api_.close(h);
        } else {
            f.why = rc == kAccess ? "no permission to open it: install the udev rule (sudo make install-udev) and plug it in again"
                                  : "cannot open it (" + errorName(rc) + ")";
        }
        out.push_back(f);
    }
    api_.freeDeviceList(list, 1);
    return out;
}

}  // namespace hs::usb
