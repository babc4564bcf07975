#include "common/platform/realtime_kit.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cstdint>
#include <stdexcept>

#include "common/platform/dbus_connection.hpp"

namespace hs {

namespace {

const char* const kService = "org.freedesktop.RealtimeKit1";
const char* const kPath = "/org/freedesktop/RealtimeKit1";

std::int64_t property(DBusConnection& bus, const char* name) {
    DBusWriter w;
    w.string(kService);
    w.string(name);
    const DBusReply r = bus.call(kService, kPath, "org.freedesktop.DBus.Properties", "Get", "ss", w.bytes());
    if (r.error) throw std::runtime_error(r.errorName + (r.firstString().empty() ? "" : ": " + r.firstString()));
    return r.firstInteger();
}

}  // namespace

RealtimeGrant askRealtimeKit(long tid, int priority, const std::string& busAddress, double timeout) {
    RealtimeGrant g;
    try {
        DBusConnection bus(busAddress, timeout);
        const auto most = static_cast<int>(property(bus, "MaxRealtimePriority"));
        const std::int64_t rttime = property(bus, "RTTimeUSecMax");
        rlimit limit{};
        if (rttime > 0 && getrlimit(RLIMIT_RTTIME, &limit) == 0 &&
            (limit.rlim_max == RLIM_INFINITY || limit.rlim_max > static_cast<rlim_t>(rttime))) {
            limit.rlim_cur = limit.rlim_max = static_cast<rlim_t>(rttime);
            if (setrlimit(RLIMIT_RTTIME, &limit) != 0) throw std::runtime_error("could not set RLIMIT_RTTIME");
        }
        g.priority = std::max(1, std::min(priority, most));
        DBusWriter w;
        w.u64(static_cast<std::uint64_t>(tid));
        w.u32(static_cast<std::uint32_t>(g.priority));
        const DBusReply r = bus.call(kService, kPath, kService, "MakeThreadRealtime", "tu", w.bytes());
        if (r.error) throw std::runtime_error(r.errorName + (r.firstString().empty() ? "" : ": " + r.firstString()));
        g.granted = true;
    } catch (const std::exception& e) {
        g.granted = false;
        g.priority = 0;
        g.why = e.what();
    }
    return g;
}

}  // namespace hs
