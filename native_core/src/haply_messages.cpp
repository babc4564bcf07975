#include "haply_messages.hpp"

#include <simdjson.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string_view>

namespace hs::haply {

namespace od = simdjson::ondemand;

struct Reader::Parser {
    od::parser parser{kMaxMessage};
};

Reader::Reader() : parser_(std::make_unique<Parser>()), buffer_(new char[kMaxMessage + simdjson::SIMDJSON_PADDING]()) {
    if (parser_->parser.allocate(kMaxMessage)) throw std::bad_alloc();
}

Reader::~Reader() = default;

namespace {
bool readVec(od::object parent, const char* key, Vec3& out) {
    od::object v;
    if (parent[key].get_object().get(v)) return false;
    double x, y, z;
    if (v["x"].get_double().get(x) || v["y"].get_double().get(y) || v["z"].get_double().get(z)) return false;
    out = Vec3(x, y, z);
    return out.allFinite();
}

// A Verse Grip's button ("button": bool) or a wireless one's ("buttons": {"a": bool, ...}).
std::uint32_t gripButtons(od::object state) {
    bool pressed = false;
    if (!state["button"].get_bool().get(pressed)) return pressed ? 1u : 0u;
    od::object buttons;
    if (state["buttons"].get_object().get(buttons)) return 0;
    std::uint32_t bits = 0, bit = 1;
    for (auto field : buttons) {
        bool b = false;
        if (!field.value().get_bool().get(b) && b) bits |= bit;
        bit <<= 1;
    }
    return bits;
}
}  // namespace

bool Reader::inventory(std::size_t n, std::vector<Inverse3Info>& out, std::string& why) {
    out.clear();
    if (n > kMaxMessage) {
        why = "message too long";
        return false;
    }
    od::document doc;
    od::array devices;
    if (parser_->parser.iterate(buffer_.get(), n, kMaxMessage + simdjson::SIMDJSON_PADDING).get(doc) ||
        doc["inverse3"].get_array().get(devices)) {
        why = "not an inventory (no \"inverse3\" list)";
        return false;
    }
    for (auto item : devices) {
        od::object device;
        std::string_view id;
        if (item.get_object().get(device) || device["device_id"].get_string().get(id)) {
            why = "an Inverse3 entry without a device_id";
            return false;
        }
        Inverse3Info info;
        info.deviceId = std::string(id);
        od::object status;
        if (!device["status"].get_object().get(status)) {
            bool v = false;
            if (!status["ready"].get_bool().get(v)) info.ready = v;
            if (!status["in_use"].get_bool().get(v)) info.inUse = v;
            if (!status["calibrated"].get_bool().get(v)) info.calibrated = v;
        }
        out.push_back(std::move(info));
    }
    return true;
}

bool Reader::state(std::size_t n, const char* deviceId, State& state) {
    if (n > kMaxMessage) return false;
    od::document doc;
    od::array devices;
    if (parser_->parser.iterate(buffer_.get(), n, kMaxMessage + simdjson::SIMDJSON_PADDING).get(doc) ||
        doc["inverse3"].get_array().get(devices))
        return false;
    State next = state;
    next.found = false;
    for (auto item : devices) {
        od::object device, s;
        std::string_view id;
        if (item.get_object().get(device) || device["device_id"].get_string().get(id)) return false;
        if (id != deviceId) continue;
        if (device["state"].get_object().get(s) || !readVec(s, "cursor_position", next.position)) return false;
        Vec3 v;
        if (readVec(s, "cursor_velocity", v)) next.velocity = v;
        next.found = true;
        break;
    }
    if (!next.found) return false;
    for (const char* grips : {"verse_grip", "wireless_verse_grip"}) {
        od::array list;
        if (doc[grips].get_array().get(list)) continue;
        for (auto item : list) {  // the first grip's buttons
            od::object grip, s;
            if (!item.get_object().get(grip) && !grip["state"].get_object().get(s)) next.buttons = gripButtons(s);
            break;
        }
        break;
    }
    state = next;
    return true;
}

std::size_t writeForceCommand(char* out, std::size_t capacity, const char* deviceId, const Vec3& force, bool first) {
    const Vec3 f = force.allFinite() ? force : Vec3::Zero();
    const char* session = first ? "\"session\":{\"configure\":{\"profile\":{\"name\":\"org.hapticsculpt.freecad\"},"
                                  "\"basis\":{\"permutation\":\"XYZ\"}}},"
                                : "";
    const int n = std::snprintf(out, capacity,
                                "{%s\"inverse3\":[{\"device_id\":\"%s\",\"commands\":{\"set_cursor_force\":"
                                "{\"vector\":{\"x\":%.6f,\"y\":%.6f,\"z\":%.6f}}}}]}",
                                session, deviceId, f.x(), f.y(), f.z());
    return n > 0 && static_cast<std::size_t>(n) < capacity ? static_cast<std::size_t>(n) : 0;
}

}  // namespace hs::haply
