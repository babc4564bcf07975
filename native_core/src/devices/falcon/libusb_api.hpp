// libusb-1.0, loaded at run time from Debian's libusb-1.0-0 (libusb-1.0.so.0): the Falcon is the
// only user, so nothing needs it to build and the wheel does not depend on it; the tests load a
// fake libusb through the same path. Only the calls and types used are declared (libusb.h's ABI,
// stable across 1.0.x).
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/platform/shared_library.hpp"

namespace hs::usb {

struct Context;       // libusb_context
struct Device;        // libusb_device
struct DeviceHandle;  // libusb_device_handle

struct DeviceDescriptor {  // libusb_device_descriptor
    std::uint8_t bLength, bDescriptorType;
    std::uint16_t bcdUSB;
    std::uint8_t bDeviceClass, bDeviceSubClass, bDeviceProtocol, bMaxPacketSize0;
    std::uint16_t idVendor, idProduct, bcdDevice;
    std::uint8_t iManufacturer, iProduct, iSerialNumber, bNumConfigurations;
};

enum Error : int { kSuccess = 0, kIo = -1, kAccess = -3, kNoDevice = -4, kNotFound = -5, kBusy = -6, kTimeout = -7, kPipe = -9 };

struct Api {
    int (*init)(Context**);
    void (*exit)(Context*);
    long (*getDeviceList)(Context*, Device***);
    void (*freeDeviceList)(Device**, int);
    int (*getDeviceDescriptor)(Device*, DeviceDescriptor*);
    std::uint8_t (*getBusNumber)(Device*);
    std::uint8_t (*getDeviceAddress)(Device*);
    int (*open)(Device*, DeviceHandle**);
    void (*close)(DeviceHandle*);
    int (*kernelDriverActive)(DeviceHandle*, int);
    int (*detachKernelDriver)(DeviceHandle*, int);
    int (*claimInterface)(DeviceHandle*, int);
    int (*releaseInterface)(DeviceHandle*, int);
    int (*controlTransfer)(DeviceHandle*, std::uint8_t, std::uint8_t, std::uint16_t, std::uint16_t, unsigned char*,
                           std::uint16_t, unsigned int);
    int (*bulkTransfer)(DeviceHandle*, unsigned char, unsigned char*, int, int*, unsigned int);
    const char* (*errorName)(int);
};

/// libusb loaded, with a context of its own (released with the last copy).
class Library {
public:
    /// Loads `names` (default: Debian's libusb-1.0.so.0) and makes a context; std::runtime_error
    /// saying what is missing.
    static std::shared_ptr<Library> load(const std::vector<std::string>& names = {});
    ~Library();
    Library(const Library&) = delete;
    Library& operator=(const Library&) = delete;
    const Api& api() const { return api_; }
    Context* context() const { return context_; }
    std::string errorName(int code) const;

    /// One attached device with the vendor and product id asked for.
    struct Found {
        int bus = 0, address = 0;
        bool openable = false;   ///< false: see why
        std::string why;         ///< e.g. no permission
    };
    /// The attached devices with `vendor:product`; each opened once (and closed) to see if it can be.
    std::vector<Found> find(std::uint16_t vendor, std::uint16_t product) const;

private:
    explicit Library(SharedLibrary lib);
    SharedLibrary lib_;
    Api api_{};
    Context* context_ = nullptr;
};

}  // namespace hs::usb
