#include "devices/haply/haply_messages.hpp"

#include <simdjson.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string_view>

namespace hs::haply {

namespace dom = simdjson::dom;

// The DOM parser validates a whole message before anything is read from it, so a malformed message
// is refused as a whole. (The on-demand parser reads as it goes: a message broken after the fields
// already read left its iterator in an error state that a later lookup asserted on; two such
// messages are kept in fuzz/findings/fuzz_haply_messages.)
struct Reader::Parser {
    dom::parser parser{kMaxMessage};
};

Reader::Reader() : parser_(std::make_unique<Parser>()), buffer_(new char[kMaxMessage + simdjson::SIMDJSON_PADDING]()) {
    if (parser_->parser.allocate(kMaxMessage)) throw std::bad_alloc();
}

Reader::~Reader() = default;

namespace {
simdjson::error_code readVec(dom::object parent, const char* key, Vec3& out) {
    dom::object v;
    double x = 0, y = 0, z = 0;
    simdjson::error_code e = parent[key].get_object().get(v);
    if (!e) e = v["x"].get_double().get(x);
    if (!e) e = v["y"].get_double().get(y);
    if (!e) e = v["z"].get_double().get(z);
    if (e) return e;
    out = Vec3(x, y, z);
    return out.allFinite() ? simdjson::SUCCESS : simdjson::INCORRECT_TYPE;
}

// A Verse Grip's button ("button": bool) or a wireless one's ("buttons": {"a": bool, ...}).
simdjson::error_code gripButtons(dom::object state, std::uint32_t& bits) {
    bool pressed = false;
    simdjson::error_code e = state["button"].get_bool().get(pressed);
    if (!e) {
        bits = pressed ? 1u : 0u;
        return e;
    }
    if (e != simdjson::NO_SUCH_FIELD) return e;
    dom::object buttons;
    if ((e = state["buttons"].get_object().get(buttons))) return e;
    std::uint32_t next = 0, bit = 1;
    for (const dom::key_value_pair field : buttons) {
        bool b = false;
        if ((e = field.value.get_bool().get(b))) return e;
        if (b) next |= bit;
        bit <<= 1;
    }
    bits = next;
    return simdjson::SUCCESS;
}

// The "inverse3" list of a whole, valid message.
bool devicesOf(dom::parser& parser, const char* buffer, std::size_t n, dom::element& doc, dom::array& devices) {
    return !parser.parse(buffer, n, false).get(doc) && !doc["inverse3"].get_array().get(devices);
}
}  // namespace

bool Reader::inventory(std::size_t n, std::vector<Inverse3Info>& out, std::string& why) {
    out.clear();
    if (n > kMaxMessage) {
        why = "message too long";
        return false;
    }
    dom::element doc;
    dom::array devices;
    if (!devicesOf(parser_->parser, buffer_.get(), n, doc, devices)) {
        why = "not an inventory (no \"inverse3\" list)";
        return false;
    }
    for (const dom::element item : devices) {
        dom::object device;
        std::string_view id;
        if (item.get_object().get(device) || device["device_id"].get_string().get(id)) {
            why = "an Inverse3 entry without a device_id";
            out.clear();
            return false;
        }
        Inverse3Info info;
        info.deviceId = std::string(id);
        dom::object status;
        simdjson::error_code e = device["status"].get_object().get(status);
        if (e == simdjson::NO_SUCH_FIELD) e = simdjson::SUCCESS;
        else if (!e) {
            for (auto [key, flag] : {std::pair<const char*, bool*>{"ready", &info.ready}, {"in_use", &info.inUse},
                                     {"calibrated", &info.calibrated}}) {
                bool v = false;
                e = status[key].get_bool().get(v);
                if (!e) *flag = v;
                else if (e == simdjson::NO_SUCH_FIELD) e = simdjson::SUCCESS;
                else break;
            }
        }
        if (e) {
            why = "a malformed status";
            out.clear();
            return false;
        }
        out.push_back(std::move(info));
    }
    return true;
}

bool Reader::state(std::size_t n, const char* deviceId, State& state) {
    if (n > kMaxMessage) return false;
    dom::element doc;
    dom::array devices;
    if (!devicesOf(parser_->parser, buffer_.get(), n, doc, devices)) return false;
    State next = state;
    next.found = false;
    for (const dom::element item : devices) {
        dom::object device, st;
        std::string_view id;
        if (item.get_object().get(device) || device["device_id"].get_string().get(id)) return false;
        if (id != deviceId) continue;
        if (device["state"].get_object().get(st) || readVec(st, "cursor_position", next.position)) return false;
        Vec3 v;
        const simdjson::error_code e = readVec(st, "cursor_velocity", v);
        if (!e) next.velocity = v;
        else if (e != simdjson::NO_SUCH_FIELD) return false;
        next.found = true;
        break;
    }
    if (!next.found) return false;
    for (const char* grips : {"verse_grip", "wireless_verse_grip"}) {
        dom::array list;
        simdjson::error_code e = doc[grips].get_array().get(list);
        if (e == simdjson::NO_SUCH_FIELD) continue;
        if (e) return false;
        for (const dom::element item : list) {  // the first grip's buttons
            dom::object grip, st;
            if ((e = item.get_object().get(grip)) || (e = grip["state"].get_object().get(st)) ||
                (e = gripButtons(st, next.buttons)))
                if (e != simdjson::NO_SUCH_FIELD) return false;
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
                                "{\"vector\":{\"x\":%.9g,\"y\":%.9g,\"z\":%.9g}}}}]}",
                                session, deviceId, f.x(), f.y(), f.z());
    return n > 0 && static_cast<std::size_t>(n) < capacity ? static_cast<std::size_t>(n) : 0;
}

}  // namespace hs::haply
