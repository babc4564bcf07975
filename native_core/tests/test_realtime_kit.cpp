// RealtimeKit's client where there is nothing to ask: it says why, and never throws. (Granting is
// tested against a stand-in rtkit on a bus of its own: tests/test_realtime_kit.py.)
#include <gtest/gtest.h>

#include <string>

#include "common/platform/dbus_connection.hpp"
#include "common/platform/realtime_kit.hpp"

using namespace hs;

TEST(RealtimeKit, NoBusIsSaidAndNotThrown) {
    const RealtimeGrant g = askRealtimeKit(1, 20, "unix:path=/nonexistent/hs/system_bus_socket", 0.2);
    EXPECT_FALSE(g.granted);
    EXPECT_EQ(g.priority, 0);
    EXPECT_NE(g.why.find("no D-Bus system bus at unix:path=/nonexistent/hs/system_bus_socket"), std::string::npos) << g.why;
    const RealtimeGrant none = askRealtimeKit(1, 20, "tcp:host=localhost,port=1", 0.2);  // (unix sockets only)
    EXPECT_FALSE(none.granted);
    EXPECT_NE(none.why.find("no D-Bus system bus"), std::string::npos) << none.why;
}

TEST(DBusWriter, MarshalsAlignedLittleEndian) {
    DBusWriter w;
    w.string("ab");  // length 2, "ab", NUL: 7 bytes
    w.u64(0x0102030405060708ULL);  // aligned to 8: one byte of padding
    w.u32(9);
    const std::vector<std::uint8_t> expected{2, 0, 0, 0, 'a', 'b', 0, 0, 8, 7, 6, 5, 4, 3, 2, 1, 9, 0, 0, 0};
    EXPECT_EQ(w.bytes(), expected);
}

TEST(DBusReply, ReadsAPropertyVariantAndAnErrorMessage) {
    DBusReply property;
    property.signature = "v";
    property.body = {1, 'x', 0, 0, 0, 0, 0, 0, 0x40, 0x0d, 0x03, 0, 0, 0, 0, 0};  // variant x = 200000
    EXPECT_EQ(property.firstInteger(), 200000);
    property.body = {1, 'i', 0, 0, 20, 0, 0, 0};
    EXPECT_EQ(property.firstInteger(), 20);
    property.body = {1, 'x', 0};  // (cut short)
    EXPECT_THROW(property.firstInteger(), std::runtime_error);
    DBusReply error;
    error.signature = "s";
    error.body = {3, 0, 0, 0, 'n', 'o', '!', 0};
    EXPECT_EQ(error.firstString(), "no!");
}
