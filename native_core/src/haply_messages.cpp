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
// simdjson's on-demand document must not be touched again after a hard error (a field that is
// merely absent is not one): every read below hands its error up.
bool hard(simdjson::error_code e) { return e && e != simdjson::NO_SUCH_FIELD; }

simdjson::error_code readVec(od::object parent, const char* key, Vec3& out) {
    od::object v;
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
simdjson::error_code gripButtons(od::object state, std::uint32_t& bits) {
    bool pressed = false;
    simdjson::error_code e = state["button"].get_bool().get(pressed);
    if (!e) {
        bits = pressed ? 1u : 0u;
        return e;
    }
    if (hard(e)) return e;
    od::object buttons;
    if ((e = state["buttons"].get_object().get(buttons))) return e;
    bits = 0;
    std::uint32_t bit = 1;
    for (auto item : buttons) {
        od::field f;
        bool b = false;
        if ((e = std::move(item).get(f)) || (e = f.value().get_bool().get(b))) return e;
        if (b) bits |= bit;
        bit <<= 1;
    }
    return simdjson::SUCCESS;
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
        simdjson::error_code e = device["status"].get_object().get(status);
        for (auto [key, flag] : {std::pair<const char*, bool*>{"ready", &info.ready}, {"in_use", &info.inUse},
                                 {"calibrated", &info.calibrated}}) {
            if (e) break;
            bool v = false;
            e = status[key].get_bool().get(v);
            if (!e) *flag = v;
            else if (!hard(e)) e = simdjson::SUCCESS;
        }
        if (hard(e)) {
            why = "a malformed status";
            return false;
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
        od::object device, st;
        std::string_view id;
        if (item.get_object().get(device) || device["device_id"].get_string().get(id)) return false;
        if (id != deviceId) continue;
        if (device["state"].get_object().get(st) || readVec(st, "cursor_position", next.position)) return false;
        Vec3 v;
        const simdjson::error_code e = readVec(st, "cursor_velocity", v);
        if (!e) next.velocity = v;
        else if (hard(e)) return false;
        next.found = true;
        break;
    }
    if (!next.found) return false;
    for (const char* grips : {"verse_grip", "wireless_verse_grip"}) {
        od::array list;
        simdjson::error_code e = doc[grips].get_array().get(list);
        if (e == simdjson::NO_SUCH_FIELD) continue;
        if (e) return false;
        for (auto item : list) {  // the first grip's buttons
            od::object grip, st;
            if ((e = item.get_object().get(grip)) || (e = grip["state"].get_object().get(st)) ||
                (e = gripButtons(st, next.buttons)))
                if (hard(e)) return false;
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
