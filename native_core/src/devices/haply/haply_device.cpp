#include "devices/haply/haply_device.hpp"

#include <libwebsockets.h>

#include <algorithm>
#include <array>
#include <condition_variable>
#include <cstring>
#include <stdexcept>

#include "devices/device_limits.hpp"

namespace hs {

void HaplySettings::validate() const {
    mapping.validate();
    if (host.empty()) throw std::invalid_argument("host: must not be empty");
    requireInRange(port, "port", 1, 65535);
    requirePositive(maxForce, "max_force", true);
    requireInRange(rateHz, "rate", 100.0, 10000.0);
    requireInRange(connectTimeout, "connect_timeout", 0.05, 60.0);
    requireInRange(staleAfter, "stale_after", 0.005, 10.0);
}

// The connection, driven by libwebsockets' service loop on the I/O thread.
struct HaplyDevice::Link {
    enum class Phase { Connecting, Inventory, Running, Failed, Closed };
    HaplyDevice* owner = nullptr;  // null when only discovering
    std::string wantedId;
    lws_context* context = nullptr;
    lws* wsi = nullptr;
    haply::Reader reader;
    std::size_t length = 0;
    bool overflow = false, first = true;
    std::array<char, LWS_PRE + 1024> out{};
    std::atomic<bool> stop{false}, wantSend{false};
    std::mutex lock;  // guards phase, why and inventory for start() (setup, not the ticks)
    std::condition_variable changed;
    Phase phase = Phase::Connecting;
    std::string why, deviceId, where;  // (where: host:port, for messages)
    std::vector<haply::Inverse3Info> inventory;
    bool inventoryRead = false;
    haply::State last;  // the I/O thread's own copy of the newest state

    void set(Phase p, std::string reason = {}) {
        {
            std::lock_guard<std::mutex> g(lock);
            if (phase == Phase::Failed || phase == Phase::Closed) return;  // the first reason stays
            phase = p;
            if (!reason.empty()) why = std::move(reason);
        }
        changed.notify_all();
        if ((p == Phase::Failed || p == Phase::Closed) && owner) owner->lost_.store(true, std::memory_order_release);
    }
    Phase current() {
        std::lock_guard<std::mutex> g(lock);
        return phase;
    }

    void message() {  // one whole message in reader.buffer()[0, length)
        const Phase p = current();
        if (p == Phase::Inventory) {
            std::vector<haply::Inverse3Info> found;
            std::string problem;
            if (!reader.inventory(length, found, problem)) return set(Phase::Failed, "Haply: the service's first message: " + problem);
            std::string chosen, reason;
            for (const auto& d : found)
                if (wantedId.empty() || d.deviceId == wantedId) {
                    chosen = d.deviceId;
                    if (d.inUse) reason = "Haply: the Inverse3 " + d.deviceId + " is in use by another program";
                    break;
                }
            {
                std::lock_guard<std::mutex> g(lock);
                inventory = found;
                inventoryRead = true;
                deviceId = chosen;
            }
            if (!owner) return set(Phase::Closed);  // discovery: the inventory is all it wanted
            if (found.empty()) return set(Phase::Failed, "Haply: the service lists no Inverse3 (is it plugged in and powered?)");
            if (chosen.empty()) return set(Phase::Failed, "Haply: the service lists no Inverse3 " + wantedId);
            if (!reason.empty()) return set(Phase::Failed, reason);
            set(Phase::Running);
            lws_callback_on_writable(wsi);  // the first command: its reply is the first state
            return;
        }
        if (p != Phase::Running || !owner) return;
        haply::State s = last;  // (what a message leaves out keeps its last value)
        if (!reader.state(length, deviceId.c_str(), s)) {
            owner->malformed_.fetch_add(1, std::memory_order_relaxed);
            return;
        }
        last = s;
        owner->state_.write(s);
        owner->updates_.fetch_add(1, std::memory_order_release);
    }

    void writeCommand() {
        Vec3 f = Vec3::Zero();
        if (owner && !owner->lost_.load(std::memory_order_relaxed))
            for (int i = 0; i < 3; ++i) f[i] = owner->force_[i].load(std::memory_order_relaxed);
        char* body = out.data() + LWS_PRE;
        const std::size_t n = haply::writeForceCommand(body, out.size() - LWS_PRE, deviceId.c_str(), f, first);
        if (n == 0) return;
        first = false;
        if (lws_write(wsi, reinterpret_cast<unsigned char*>(body), n, LWS_WRITE_TEXT) < static_cast<int>(n))
            set(Phase::Closed, "Haply: the link to the service broke");
    }

    void unreachable(const std::string& reason) {
        set(Phase::Failed, "Haply: cannot reach the Inverse Service at " + where + " (" + reason + "): is it running?");
    }
    // A link that closes before it was ever up could not reach the service (libwebsockets on Windows
    // reports a refused connection so, with no connection error first).
    void closed(const char* reason) {
        if (current() == Phase::Connecting) unreachable("refused");
        else set(Phase::Closed, reason);
    }

    static int callback(lws* w, lws_callback_reasons reason, void*, void* in, size_t len) {
        auto* self = static_cast<Link*>(lws_context_user(lws_get_context(w)));
        if (!self) return 0;
        switch (reason) {
            case LWS_CALLBACK_CLIENT_ESTABLISHED:
                self->set(Phase::Inventory);
                break;
            case LWS_CALLBACK_CLIENT_RECEIVE: {
                if (self->length + len > haply::kMaxMessage) self->overflow = true;
                else std::memcpy(self->reader.buffer() + self->length, in, len);
                self->length += len;
                if (lws_is_final_fragment(w) && lws_remaining_packet_payload(w) == 0) {
                    if (self->overflow && self->owner) self->owner->malformed_.fetch_add(1, std::memory_order_relaxed);
                    else if (!self->overflow) self->message();
                    self->length = 0;
                    self->overflow = false;
                }
                break;
            }
            case LWS_CALLBACK_CLIENT_WRITEABLE:
                self->writeCommand();
                break;
            case LWS_CALLBACK_EVENT_WAIT_CANCELLED:
                if (self->wsi && self->wantSend.exchange(false) && self->current() == Phase::Running) lws_callback_on_writable(self->wsi);
                break;
            case LWS_CALLBACK_CLIENT_CONNECTION_ERROR:
                self->unreachable(in ? static_cast<const char*>(in) : "no reason");
                break;
            case LWS_CALLBACK_CLIENT_CLOSED:
                self->closed("Haply: the service closed the link");
                break;
            case LWS_CALLBACK_WSI_DESTROY:
                self->wsi = nullptr;
                self->closed("Haply: the link to the service closed");
                break;
            default:
                break;
        }
        return 0;
    }

    bool connect(const std::string& host, int port) {
        where = host + ":" + std::to_string(port);
        static const lws_protocols protocols[] = {{"haply", &Link::callback, 0, 0, 0, nullptr, 0}, {nullptr, nullptr, 0, 0, 0, nullptr, 0}};
        lws_set_log_level(LLL_ERR, nullptr);
        lws_context_creation_info info{};
        info.port = CONTEXT_PORT_NO_LISTEN;
        info.protocols = protocols;
        info.user = this;
        context = lws_create_context(&info);
        if (!context) {
            set(Phase::Failed, "Haply: cannot create the WebSocket context");
            return false;
        }
        lws_client_connect_info ci{};
        ci.context = context;
        ci.address = host.c_str();
        ci.port = port;
        ci.path = "/";
        ci.host = host.c_str();
        ci.origin = host.c_str();
        ci.pwsi = &wsi;
        if (!lws_client_connect_via_info(&ci)) {
            set(Phase::Failed, "Haply: cannot connect to " + where);
            return false;
        }
        return true;
    }
    void run() {
        while (!stop.load(std::memory_order_acquire) && lws_service(context, 0) >= 0) {
        }
    }
    // Waits until the phase is one of `until` (setup only); false on timeout.
    bool waitFor(std::initializer_list<Phase> until, double seconds) {
        std::unique_lock<std::mutex> g(lock);
        return changed.wait_for(g, std::chrono::duration<double>(seconds), [&] {
            return std::find(until.begin(), until.end(), phase) != until.end();
        });
    }
    void close(std::thread& io) {
        stop.store(true, std::memory_order_release);
        if (context) lws_cancel_service(context);
        if (io.joinable()) io.join();
        if (context) lws_context_destroy(context);
        context = nullptr;
    }
};

HaplyDevice::HaplyDevice(HaplySettings settings) : settings_(std::move(settings)) { settings_.validate(); }

HaplyDevice::~HaplyDevice() { stop(); }

DeviceCaps HaplyDevice::caps() const {
    DeviceCaps c;
    c.dof = 3;
    c.forceOutput = true;
    c.rateHz = 0;  // paced by the haptic loop: one command, one state
    // Haply publishes no force rating or stiffness for the Inverse3 that this project could find:
    // it gets the table's softest row until one is measured (the service's own force gate and
    // safety monitoring apply on top).
    // (a copy: GCC 14 took the name's temporary string for what a reference would point into)
    const DeviceLimits row = limitsFor("Inverse3");
    c.maxForce = settings_.mapping.sessionForce(settings_.maxForce > 0 ? settings_.maxForce : row.ratedForce);
    c.maxStiffness = settings_.mapping.sessionStiffness(passiveStiffnessFor(row, settings_.rateHz));
    return c;
}

void HaplyDevice::start() {
    stop();
    lost_.store(false);
    updates_.store(0);
    for (auto& f : force_) f.store(0.0);
    link_ = std::make_unique<Link>();
    link_->owner = this;
    link_->wantedId = settings_.deviceId;
    if (link_->connect(settings_.host, settings_.port)) io_ = std::thread([this] { link_->run(); });
    const bool answered = link_->waitFor({Link::Phase::Running, Link::Phase::Failed, Link::Phase::Closed}, settings_.connectTimeout);
    std::string why;
    if (!answered) why = "Haply: no answer from the Inverse Service at " + settings_.host + ":" + std::to_string(settings_.port) +
                         " within " + std::to_string(settings_.connectTimeout) + " s";
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(settings_.connectTimeout);
    while (why.empty() && updates_.load(std::memory_order_acquire) == 0) {  // the first state
        if (link_->current() != Link::Phase::Running) {
            std::lock_guard<std::mutex> g(link_->lock);
            why = link_->why;
        } else if (std::chrono::steady_clock::now() > end) {
            why = "Haply: the service sent no state for the Inverse3";
        } else {
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
    }
    if (!why.empty()) {
        link_->close(io_);
        link_.reset();
        throw std::runtime_error(why);
    }
    {
        std::lock_guard<std::mutex> g(link_->lock);
        deviceId_ = link_->deviceId;
    }
    state_.update();
    centre_ = state_.front().position;
    forceLimit_ = settings_.maxForce > 0 ? settings_.maxForce : limitsFor("Inverse3").ratedForce;
    seen_ = 0;
    lastUpdate_ = std::chrono::steady_clock::now();
}

void HaplyDevice::stop() {
    if (!link_) return;
    for (auto& f : force_) f.store(0.0);
    if (!lost_.load()) {  // the last command a zero force (the service idles the device once they stop)
        const std::uint64_t before = updates_.load();
        link_->wantSend.store(true);
        lws_cancel_service(link_->context);
        const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(100);
        while (updates_.load() == before && !lost_.load() && std::chrono::steady_clock::now() < end)
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    link_->close(io_);
    link_.reset();
}

bool HaplyDevice::sample(double, DeviceSample& out) {
    if (lost_.load(std::memory_order_acquire) || !link_) return false;
    state_.update();
    const haply::State& s = state_.front();
    const std::uint64_t n = updates_.load(std::memory_order_acquire);
    const auto now = std::chrono::steady_clock::now();
    if (n != seen_) {
        seen_ = n;
        lastUpdate_ = now;
    } else if (std::chrono::duration<double>(now - lastUpdate_).count() > settings_.staleAfter) {
        lost_.store(true);  // the service stopped answering
        return false;
    }
    out.position = settings_.mapping.position(1000.0 * (s.position - centre_));  // Haply's frame is the document's
    out.orientation = Eigen::Quaterniond::Identity();
    out.buttons = s.buttons;
    out.valid = true;
    return true;
}

void HaplyDevice::setForce(const Vec3& force) {
    if (!link_) return;
    Vec3 f = force.allFinite() ? settings_.mapping.newtons(force) : Vec3::Zero();
    if (f.norm() > forceLimit_) f *= forceLimit_ / f.norm();
    for (int i = 0; i < 3; ++i) force_[i].store(f[i], std::memory_order_relaxed);
    link_->wantSend.store(true, std::memory_order_release);
    lws_cancel_service(link_->context);  // the I/O thread sends it as the next command
}

std::vector<haply::Inverse3Info> HaplyDevice::discover(const std::string& host, int port, double timeout) {
    Link link;
    std::thread io;
    if (link.connect(host, port)) io = std::thread([&link] { link.run(); });
    const bool answered = link.waitFor({Link::Phase::Failed, Link::Phase::Closed}, timeout);
    link.close(io);
    std::lock_guard<std::mutex> g(link.lock);
    if (!link.inventoryRead)
        throw std::runtime_error(!answered || link.why.empty()
                                     ? "Haply: no answer from the Inverse Service at " + host + ":" + std::to_string(port)
                                     : link.why);
    return link.inventory;
}

}  // namespace hs
