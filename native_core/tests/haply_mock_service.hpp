// A mock Haply Inverse Service for the tests: a WebSocket server on loopback (libwebsockets, a
// port the kernel picks) speaking the simulation channel's JSON as Haply documents it: the
// inventory on connecting, then exactly one state update per message received. Behind it an
// Inverse3 emulated as a grip of mass m with damping, held by a hand that follows a script
// (fake_vendor/fake_mechanism.hpp), driven by the set_cursor_force each command carries, one
// 1 ms step per command; a Verse Grip whose button follows the script. Faults on request: a
// malformed reply every n-th, the link closed after n commands, the device in use.
#pragma once
#include <libwebsockets.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "fake_vendor/fake_mechanism.hpp"

namespace hs::haply {

class MockService {
public:
    explicit MockService(std::vector<std::string> devices = {"049D"}) : devices_(std::move(devices)) {
        static const lws_protocols protocols[] = {{"haply", &MockService::callback, 0, 0, 0, nullptr, 0}, {nullptr, nullptr, 0, 0, 0, nullptr, 0}};
        lws_set_log_level(LLL_ERR, nullptr);
        lws_context_creation_info info{};
        info.port = 0;  // the kernel picks
        // Loopback only: an interface name on Linux (libwebsockets 4.3 takes no address here); Windows
        // names no interface "lo", and the 4.1 built for it takes the address.
#ifdef _WIN32
        info.iface = "127.0.0.1";
#else
        info.iface = "lo";
#endif
        info.options = LWS_SERVER_OPTION_DISABLE_IPV6;
        info.protocols = protocols;
        info.user = this;
        context_ = lws_create_context(&info);
        if (!context_) throw std::runtime_error("mock service: no context");
        port_ = lws_get_vhost_listen_port(lws_get_vhost_by_name(context_, "default"));
        mechanism.mass = 0.2;
        thread_ = std::thread([this] {
            while (!stop_.load() && lws_service(context_, 0) >= 0) {
            }
        });
    }
    ~MockService() {
        stop_.store(true);
        lws_cancel_service(context_);
        thread_.join();
        lws_context_destroy(context_);
    }
    int port() const { return port_; }

    // set before the client connects, or under lock()
    std::recursive_mutex lock;  // (libwebsockets 4.3 calls back from inside its own calls: re-entrant)
    fake::Mechanism mechanism;  // Haply's frame, m
    long malformedEvery = 0, closeAfter = -1;
    bool inUse = false;
    // The mechanism steps once per command (a tick-by-tick test's clock), or with the wall clock, as
    // an Inverse3 runs whatever the link's rate (a session: Wine's sockets carry a few hundred
    // commands a second, which would slow the hand's script as much).
    bool realTime = false;
    // what the test looks at (under lock)
    long commands = 0, repliesSent = 0, connections = 0;
    std::string firstCommand;
    double lastForce[3] = {0, 0, 0};

private:
    static int callback(lws* wsi, lws_callback_reasons reason, void*, void* in, size_t len) {
        auto* self = static_cast<MockService*>(lws_context_user(lws_get_context(wsi)));
        if (!self) return 0;
        std::lock_guard<std::recursive_mutex> g(self->lock);
        switch (reason) {
            case LWS_CALLBACK_ESTABLISHED:
                ++self->connections;
                self->pending_ = 0;
                self->inventoryDue_ = true;
                self->rxLength_ = 0;
                lws_callback_on_writable(wsi);
                break;
            case LWS_CALLBACK_RECEIVE:
                if (self->rxLength_ + len < self->rx_.size()) {
                    std::memcpy(self->rx_.data() + self->rxLength_, in, len);
                    self->rxLength_ += len;
                }
                if (lws_is_final_fragment(wsi) && lws_remaining_packet_payload(wsi) == 0) {
                    self->rx_[self->rxLength_] = 0;
                    self->command(self->rx_.data());
                    self->rxLength_ = 0;
                    if (self->closeAfter >= 0 && self->commands >= self->closeAfter) return -1;  // drop the link
                    ++self->pending_;
                    lws_callback_on_writable(wsi);
                }
                break;
            case LWS_CALLBACK_SERVER_WRITEABLE: {
                // (fixed buffers: the mock allocates nothing per message, so a test can count the
                // client's allocations across all threads)
                char* body = self->tx_.data() + LWS_PRE;
                const std::size_t room = self->tx_.size() - LWS_PRE;
                std::size_t n = 0;
                if (self->inventoryDue_) {
                    n = self->message(true, body, room);
                    self->inventoryDue_ = false;
                } else if (self->pending_ > 0) {
                    --self->pending_;
                    ++self->repliesSent;
                    if (self->malformedEvery > 0 && self->repliesSent % self->malformedEvery == 0)
                        n = static_cast<std::size_t>(std::snprintf(body, room, "{\"inverse3\":[{\"device_id\":\"049D\",\"state\":{\"cursor_"));
                    else
                        n = self->message(false, body, room);
                } else {
                    break;
                }
                if (lws_write(wsi, reinterpret_cast<unsigned char*>(body), n, LWS_WRITE_TEXT) < static_cast<int>(n)) return -1;
                if (self->pending_ > 0) lws_callback_on_writable(wsi);
                break;
            }
            default:
                break;
        }
        return 0;
    }

    void command(const char* text) {
        if (commands == 0) firstCommand = text;
        ++commands;
        const char* v = std::strstr(text, "\"set_cursor_force\":{\"vector\":{\"x\":");
        double f[3] = {0, 0, 0};
        if (v) std::sscanf(v, "\"set_cursor_force\":{\"vector\":{\"x\":%lf,\"y\":%lf,\"z\":%lf", &f[0], &f[1], &f[2]);
        for (int i = 0; i < 3; ++i) lastForce[i] = mechanism.force[i] = f[i];
        int steps = 1;
        if (realTime) {
            const auto now = std::chrono::steady_clock::now();
            if (commands == 1) clock_ = now;
            const auto dt = std::chrono::duration<double>(mechanism.dt);
            steps = static_cast<int>(std::min(50.0, std::floor((now - clock_) / dt)));
            clock_ = steps == 50 ? now : clock_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(steps * dt);
        }
        for (int k = 0; k < steps; ++k) mechanism.step();
    }

    std::size_t message(bool inventory, char* out, std::size_t room) const {
        std::size_t n = 0;
        auto put = [&](const char* format, auto... args) {
            const int k = std::snprintf(out + n, room - n, format, args...);
            if (k > 0) n = std::min(room - 1, n + static_cast<std::size_t>(k));
        };
        put("%s", inventory ? "{\"session_id\":7,\"inverse3\":[" : "{\"inverse3\":[");
        for (std::size_t k = 0; k < devices_.size(); ++k)
            put("%s{\"device_id\":\"%s\",%s\"state\":{\"cursor_position\":{\"x\":%.9g,\"y\":%.9g,\"z\":%.9g},"
                "\"cursor_velocity\":{\"x\":%.9g,\"y\":%.9g,\"z\":%.9g},\"control_mode\":\"cartesian\"},"
                "\"status\":{\"calibrated\":true,\"in_use\":%s,\"power_supply\":true,\"ready\":true,\"started\":true}}",
                k ? "," : "", devices_[k].c_str(),
                inventory ? "\"config\":{\"type\":\"inverse3\",\"handedness\":\"right\",\"basis\":{\"permutation\":\"XYZ\"}}," : "",
                mechanism.tip[0], mechanism.tip[1], mechanism.tip[2], mechanism.velocity[0], mechanism.velocity[1],
                mechanism.velocity[2], inUse ? "true" : "false");
        put("],\"verse_grip\":[{\"device_id\":\"61548\",\"state\":{\"button\":%s,\"hall\":0,"
            "\"orientation\":{\"x\":0,\"y\":0,\"z\":0,\"w\":1}}}]}", mechanism.buttons() ? "true" : "false");
        return n;
    }

    std::vector<std::string> devices_;
    lws_context* context_ = nullptr;
    int port_ = 0;
    std::thread thread_;
    std::atomic<bool> stop_{false};
    std::array<char, 1 << 16> rx_{};
    std::array<char, LWS_PRE + (1 << 14)> tx_{};
    std::size_t rxLength_ = 0;
    long pending_ = 0;
    bool inventoryDue_ = false;
    std::chrono::steady_clock::time_point clock_;  // the mechanism's time, when realTime
};

}  // namespace hs::haply
