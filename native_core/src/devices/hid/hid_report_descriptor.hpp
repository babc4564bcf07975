// A HID report descriptor parser (HID 1.11, section 6.2.2): the fields of every input, output and
// feature report with their bit positions, so drivers read the layout from the device instead of
// hard-coding it (report IDs and field sizes differ between devices).
#pragma once
#include <cstdint>
#include <vector>

namespace hs {

enum class ReportType : std::uint8_t { Input, Output, Feature };

/// One main item's fields: `count` fields of `size` bits from `bitOffset` (after the ID byte).
struct HidField {
    ReportType type = ReportType::Input;
    std::uint8_t reportId = 0;
    std::uint16_t usagePage = 0;
    std::vector<std::uint32_t> usages;       ///< one per field (variable) or the array's choices
    std::uint32_t usageMin = 0, usageMax = 0;  ///< a usage range, if given
    std::vector<std::uint32_t> collections;  ///< enclosing collections' usages (page << 16 | id), outermost first
    std::uint32_t bitOffset = 0, size = 0, count = 0;
    std::int32_t logicalMin = 0, logicalMax = 0;
    bool variable = true, constant = false;

    /// Usage (page << 16 | id) of field k (variable items), 0 if none.
    std::uint32_t usage(std::uint32_t k) const;
    bool inCollection(std::uint32_t fullUsage) const;
};

struct HidReportLayout {
    std::vector<HidField> fields;
    /// Bytes of a report including its ID byte (when the device uses IDs).
    std::size_t reportBytes(ReportType type, std::uint8_t id) const;
    bool usesReportIds = false;
    /// First field whose usage (or array choice) is `fullUsage`, inside collection `collection`
    /// (0: any); nullptr if none.
    const HidField* find(ReportType type, std::uint32_t fullUsage, std::uint32_t collection = 0) const;
};

/// Where usage `u` lives in report (type, id): a variable field's own bits, or an array field whose
/// value `choice` selects it. field == nullptr when the report has no such usage.
struct FieldSlot {
    const HidField* field = nullptr;
    std::uint32_t bit = 0;     ///< bit offset after the ID byte
    bool array = false;
    std::int64_t choice = 0;   ///< array fields: the value that selects the usage
};
FieldSlot locateField(const HidReportLayout& layout, ReportType type, std::uint8_t id, std::uint32_t u,
                      std::uint32_t collection = 0);

/// Parses a descriptor; throws std::invalid_argument on malformed input (truncated items,
/// unbalanced collections, absurd sizes).
HidReportLayout parseReportDescriptor(const std::vector<std::uint8_t>& descriptor);

/// Reads/writes a field value at bit offset `bit` (after the ID byte when IDs are used).
std::int64_t readField(const std::uint8_t* report, std::size_t bytes, std::uint32_t bit, std::uint32_t size, bool isSigned);
void writeField(std::uint8_t* report, std::size_t bytes, std::uint32_t bit, std::uint32_t size, std::int64_t value);

constexpr std::uint32_t usage(std::uint16_t page, std::uint16_t id) { return (std::uint32_t(page) << 16) | id; }

}  // namespace hs
