#include "devices/hid/hid_report_descriptor.hpp"

#include <algorithm>
#include <map>
#include <stdexcept>
#include <string>

namespace hs {

std::uint32_t HidField::usage(std::uint32_t k) const {
    if (k < usages.size()) return usages[k];
    if (!usages.empty()) return usages.back();
    if (usageMax >= usageMin && usageMax != 0) return std::min(usageMin + k, usageMax);
    return 0;
}

bool HidField::inCollection(std::uint32_t u) const {
    return std::find(collections.begin(), collections.end(), u) != collections.end();
}

std::size_t HidReportLayout::reportBytes(ReportType type, std::uint8_t id) const {
    std::uint32_t bits = 0;
    for (const auto& f : fields)
        if (f.type == type && f.reportId == id) bits = std::max(bits, f.bitOffset + f.size * f.count);
    return (bits + 7) / 8 + (usesReportIds ? 1 : 0);
}

const HidField* HidReportLayout::find(ReportType type, std::uint32_t u, std::uint32_t collection) const {
    for (const auto& f : fields) {
        if (f.type != type || (collection && !f.inCollection(collection))) continue;
        if (std::find(f.usages.begin(), f.usages.end(), u) != f.usages.end()) return &f;
        if (f.usageMax != 0 && u >= f.usageMin && u <= f.usageMax) return &f;
    }
    return nullptr;
}

FieldSlot locateField(const HidReportLayout& l, ReportType type, std::uint8_t id, std::uint32_t u,
                      std::uint32_t collection) {
    for (const auto& f : l.fields) {
        if (f.type != type || f.reportId != id || (collection && !f.inCollection(collection))) continue;
        if (f.variable) {
            for (std::uint32_t k = 0; k < f.count; ++k)
                if (f.usage(k) == u) return {&f, f.bitOffset + k * f.size, false, 0};
        } else {
            const auto it = std::find(f.usages.begin(), f.usages.end(), u);
            if (it != f.usages.end()) return {&f, f.bitOffset, true, f.logicalMin + static_cast<std::int64_t>(it - f.usages.begin())};
        }
    }
    return {};
}

namespace {
struct Globals {
    std::uint16_t usagePage = 0;
    std::int32_t logicalMin = 0, logicalMax = 0;
    std::uint32_t reportSize = 0, reportCount = 0;
    std::uint8_t reportId = 0;
};

std::uint32_t full(std::uint32_t value, std::size_t bytes, std::uint16_t page) {
    return bytes == 4 ? value : (std::uint32_t(page) << 16) | (value & 0xFFFF);
}
}  // namespace

HidReportLayout parseReportDescriptor(const std::vector<std::uint8_t>& d) {
    HidReportLayout layout;
    Globals g;
    std::vector<Globals> stack;
    std::vector<std::uint32_t> usages, collections;
    std::uint32_t usageMin = 0, usageMax = 0;
    std::map<std::pair<int, int>, std::uint32_t> offsets;  // (type, id) -> next bit
    size_t i = 0;
    while (i < d.size()) {
        const std::uint8_t prefix = d[i];
        if (prefix == 0xFE) throw std::invalid_argument("descriptor: long items are not supported");
        const std::size_t bytes = (prefix & 3) == 3 ? 4 : (prefix & 3);
        if (i + 1 + bytes > d.size()) throw std::invalid_argument("descriptor: truncated item at byte " + std::to_string(i));
        std::uint32_t value = 0;
        for (std::size_t k = 0; k < bytes; ++k) value |= std::uint32_t(d[i + 1 + k]) << (8 * k);
        std::int32_t svalue = static_cast<std::int32_t>(value);
        if (bytes == 1) svalue = static_cast<std::int8_t>(value);
        if (bytes == 2) svalue = static_cast<std::int16_t>(value);
        const std::uint8_t tag = prefix & 0xFC;
        i += 1 + bytes;
        switch (tag) {
            // main items
            case 0x80: case 0x90: case 0xB0: {  // Input, Output, Feature
                const ReportType type = tag == 0x80 ? ReportType::Input : tag == 0x90 ? ReportType::Output : ReportType::Feature;
                if (g.reportSize > 64 || g.reportCount > 4096) throw std::invalid_argument("descriptor: absurd report size or count");
                HidField f;
                f.type = type;
                f.reportId = g.reportId;
                f.usagePage = g.usagePage;
                f.usages = usages;
                f.usageMin = usageMin;
                f.usageMax = usageMax;
                f.collections = collections;
                f.size = g.reportSize;
                f.count = g.reportCount;
                f.logicalMin = g.logicalMin;
                f.logicalMax = g.logicalMax;
                f.constant = value & 1;
                f.variable = value & 2;
                auto& off = offsets[{static_cast<int>(type), g.reportId}];
                f.bitOffset = off;
                off += f.size * f.count;
                layout.fields.push_back(std::move(f));
                usages.clear();
                usageMin = usageMax = 0;
                break;
            }
            case 0xA0:  // Collection: its usage is the last local usage
                collections.push_back(usages.empty() ? 0 : usages.back());
                usages.clear();
                usageMin = usageMax = 0;
                break;
            case 0xC0:  // End Collection
                if (collections.empty()) throw std::invalid_argument("descriptor: End Collection without Collection");
                collections.pop_back();
                usages.clear();
                break;
            // global items
            case 0x04: g.usagePage = static_cast<std::uint16_t>(value); break;
            case 0x14: g.logicalMin = svalue; break;
            case 0x24: g.logicalMax = (g.logicalMin >= 0 && bytes < 4) ? static_cast<std::int32_t>(value) : svalue; break;
            case 0x74: g.reportSize = value; break;
            case 0x84:
                if (value == 0 || value > 255) throw std::invalid_argument("descriptor: report ID must be 1..255");
                g.reportId = static_cast<std::uint8_t>(value);
                layout.usesReportIds = true;
                break;
            case 0x94: g.reportCount = value; break;
            case 0xA4: stack.push_back(g); break;
            case 0xB4:
                if (stack.empty()) throw std::invalid_argument("descriptor: Pop without Push");
                g = stack.back();
                stack.pop_back();
                break;
            case 0x34: case 0x44: case 0x54: case 0x64: break;  // physical range, unit exponent, unit
            // local items
            case 0x08: usages.push_back(full(value, bytes, g.usagePage)); break;
            case 0x18: usageMin = full(value, bytes, g.usagePage); break;
            case 0x28: usageMax = full(value, bytes, g.usagePage); break;
            default: break;  // designators, strings, delimiters: not needed
        }
    }
    if (!collections.empty()) throw std::invalid_argument("descriptor: unbalanced collections");
    return layout;
}

std::int64_t readField(const std::uint8_t* r, std::size_t bytes, std::uint32_t bit, std::uint32_t size, bool isSigned) {
    std::uint64_t v = 0;
    for (std::uint32_t k = 0; k < size; ++k) {
        const std::uint32_t b = bit + k;
        if (b / 8 >= bytes) break;
        v |= std::uint64_t((r[b / 8] >> (b % 8)) & 1u) << k;
    }
    if (isSigned && size > 0 && size < 64 && (v >> (size - 1)) & 1u) v |= ~std::uint64_t(0) << size;
    return static_cast<std::int64_t>(v);
}

void writeField(std::uint8_t* r, std::size_t bytes, std::uint32_t bit, std::uint32_t size, std::int64_t value) {
    const auto v = static_cast<std::uint64_t>(value);
    for (std::uint32_t k = 0; k < size; ++k) {
        const std::uint32_t b = bit + k;
        if (b / 8 >= bytes) break;
        const std::uint8_t mask = static_cast<std::uint8_t>(1u << (b % 8));
        if ((v >> k) & 1u) r[b / 8] |= mask;
        else r[b / 8] &= static_cast<std::uint8_t>(~mask);
    }
}

}  // namespace hs
