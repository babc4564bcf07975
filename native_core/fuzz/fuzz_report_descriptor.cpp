// libFuzzer harness: arbitrary bytes as a HID report descriptor, then as a report read through
// every field it declared, and as a PID force-feedback layout. Malformed descriptors may be refused
// with std::invalid_argument; nothing may crash, read out of bounds or overflow.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "devices/hid/hid_report_descriptor.hpp"
#include "devices/hid/pid_force.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::vector<std::uint8_t> bytes(data, data + size);
    hs::HidReportLayout layout;
    try {
        layout = hs::parseReportDescriptor(bytes);
    } catch (const std::invalid_argument&) {
        return 0;
    }
    std::vector<std::uint8_t> report(64, 0);
    for (std::size_t i = 0; i < report.size() && i < size; ++i) report[i] = data[size - 1 - i];
    for (const hs::HidField& f : layout.fields) {
        (void)layout.reportBytes(f.type, f.reportId);
        for (std::uint32_t k = 0; k < f.count && k < 64; ++k) {
            const std::uint32_t bit = f.bitOffset + k * f.size;
            (void)hs::readField(report.data(), report.size(), bit, f.size, f.logicalMin < 0);
            hs::writeField(report.data(), report.size(), bit, f.size, f.logicalMax);
            const hs::FieldSlot slot = hs::locateField(layout, f.type, f.reportId, f.usage(k));
            (void)slot;
        }
    }
    try {
        const hs::PidLayout pid = hs::PidLayout::fromDescriptor(bytes);
        std::vector<std::uint8_t> out;
        hs::setPidField(pid.hid, hs::ReportType::Output, pid.constantId, hs::usage(0x0f, 0x70), 1000, out);
    } catch (const std::invalid_argument&) {
    }
    return 0;
}
