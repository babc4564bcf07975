#include "runtime/haptic_runtime.hpp"

#include "common/names.hpp"
#include "common/platform/thread_priority.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <stdexcept>

namespace hs {

namespace {
using Clock = std::chrono::steady_clock;

void atomicMax(std::atomic<double>& a, double v) {
    double cur = a.load(std::memory_order_relaxed);
    while (v > cur && !a.compare_exchange_weak(cur, v, std::memory_order_relaxed)) {
    }
}

// The q-quantile of a histogram of n + 1 bins of the given width (the last one open-ended).
double binPercentile(const std::atomic<std::uint32_t>* bins, int n, double width, double q) {
    std::uint64_t total = 0;
    for (int i = 0; i <= n; ++i) total += bins[i].load(std::memory_order_relaxed);
    if (total == 0) return 0.0;
    const auto want = static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(total)));
    std::uint64_t seen = 0;
    for (int i = 0; i <= n; ++i) {
        seen += bins[i].load(std::memory_order_relaxed);
        if (seen >= want) return (i + 0.5) * width;
    }
    return n * width;
}

bool finiteSample(const DeviceSample& s) {
    return s.position.allFinite() && s.orientation.coeffs().allFinite() && s.orientation.norm() > 0;
}
}  // namespace

HapticRuntime::HapticRuntime(std::shared_ptr<DynamicSurface> surface, std::shared_ptr<Device> device, RuntimeSettings settings)
    : surface_(std::move(surface)), device_(std::move(device)), settings_(settings),
      periodBins_(new std::atomic<std::uint32_t>[kBins + 1]), latencyBins_(new std::atomic<std::uint32_t>[kBins + 1]) {
    if (!surface_) throw std::invalid_argument("surface: required");
    if (!device_) throw std::invalid_argument("device: required");
    liveSurface_.store(surface_.get(), std::memory_order_relaxed);
    sampling_ = {surface_->g(), surface_->h(), static_cast<int>(surface_->poles().rows())};
    editsPending_.reserve(kEditSlots);
    editsTaken_.reserve(kEditSlots);
    auto positive = [](double v, const char* name) {
        if (!(v > 0) || !std::isfinite(v)) throw std::invalid_argument(std::string(name) + ": must be finite and > 0");
    };
    if (!(settings_.hapticRate >= 100 && settings_.hapticRate <= 4000))
        throw std::invalid_argument("haptic_rate: must be between 100 and 4000 Hz");
    positive(settings_.simDt, "sim_dt");
    positive(settings_.staleLimit, "stale_limit");
    positive(settings_.fadeTime, "fade_time");
    positive(settings_.maxLag, "max_lag");
    for (double v : {settings_.graphicsRate, settings_.maxForce, settings_.maxStiffness, settings_.logSeconds, settings_.idleRate})
        if (!(v >= 0) || !std::isfinite(v)) throw std::invalid_argument("settings: rates, limits and log length must be finite and >= 0");
    if (!(settings_.spin >= 0 && settings_.spin <= 0.001)) throw std::invalid_argument("spin: must be in [0, 0.001] s");
    if (settings_.simNice < 0 || settings_.simNice > 19) throw std::invalid_argument("sim_nice: must be in 0..19");
    for (int i = 0; i <= kBins; ++i) {
        periodBins_[i].store(0, std::memory_order_relaxed);
        latencyBins_[i].store(0, std::memory_order_relaxed);
    }
    requestedLimits_ = {settings_.maxForce, settings_.maxStiffness};
    applyDeviceLimits();
}

// Limits left at 0 come from the device; read again once it has started, when a device that
// learns its model on opening (a vendor's library) knows its own.
void HapticRuntime::applyDeviceLimits() {
    caps_ = device_->caps();
    settings_.maxForce = requestedLimits_[0] > 0 ? requestedLimits_[0] : caps_.maxForce > 0 ? caps_.maxForce : INFINITY;
    settings_.maxStiffness = requestedLimits_[1] > 0 ? requestedLimits_[1] : caps_.maxStiffness > 0 ? caps_.maxStiffness : INFINITY;
    limits_ = {settings_.maxForce, settings_.maxStiffness, settings_.staleLimit, settings_.fadeTime};
}

HapticRuntime::~HapticRuntime() { stop(); }

double HapticRuntime::now() const { return std::chrono::duration<double>(Clock::now() - t0_).count(); }

void AirbrushSettings::validate() const {
    if (!(radius > 0 && radius <= 1)) throw std::invalid_argument("radius: must be in (0, 1] (map coordinates)");
    if (!(factor >= 1e-6 && factor <= 1e6)) throw std::invalid_argument("factor: must be in [1e-6, 1e6]");
    if (!(strength > 0 && strength <= 1)) throw std::invalid_argument("strength: must be in (0, 1]");
    if (!(rate > 0 && rate <= 1000)) throw std::invalid_argument("rate: must be in (0, 1000] dabs per second");
}

const char* mapName(AirbrushSettings::Map map) { return nameOf(kMapNames, map); }

MaterialMap& HapticRuntime::mapOf(AirbrushSettings::Map map) {
    return map == AirbrushSettings::Map::Mass ? surface_->massMap()
         : map == AirbrushSettings::Map::Damping ? surface_->dampingMap()
         : map == AirbrushSettings::Map::Bending ? surface_->bendingMap()
         : map == AirbrushSettings::Map::Pull ? surface_->pullMap() : surface_->stiffnessMap();
}

bool HapticRuntime::takePaintedMap(PaintedMap& out) {
    if (!painted_.update()) return false;
    out = painted_.front();
    return true;
}

void HapticRuntime::setAirbrush(const AirbrushSettings& a) {
    a.validate();
    std::lock_guard<std::mutex> lock(airbrushMutex_);
    airbrushPending_ = a;
    airbrushChanged_.store(true, std::memory_order_release);
}

// Both step lengths the simulation takes: twice its step first (for catching up with real time;
// a surface for which that step is too long is stepped at dt and drops its backlog instead), then
// its step, so the step in use is the one left current.
void HapticRuntime::prepareSteps(DynamicSurface& surface) const {
    try {
        surface.prepare(2 * settings_.simDt);
    } catch (const std::invalid_argument&) {
    }
    surface.prepare(settings_.simDt);
}

std::uint64_t HapticRuntime::postEdit(SurfaceEdit edit) {
    if (edit.id == 0) throw std::invalid_argument("edit: id must be > 0");
    if (edit.next) {
        if (edit.next.get() == liveSurface_.load(std::memory_order_acquire) || edit.next->g() != sampling_[0] ||
            edit.next->h() != sampling_[1] || edit.next->poles().rows() != sampling_[2])
            throw std::invalid_argument("edit: the edited surface must be a new surface with the live one's sampling and control net");
        prepareSteps(*edit.next);  // factor here, not in the simulation thread
    }
    std::lock_guard<std::mutex> lock(editMutex_);
    editsPending_.push_back(std::move(edit));
    editsQueued_.store(true, std::memory_order_release);
    return simSteps_.load(std::memory_order_relaxed);
}

bool HapticRuntime::takeEdits(double simTime) {
    {
        std::lock_guard<std::mutex> lock(editMutex_);
        std::swap(editsPending_, editsTaken_);
        editsQueued_.store(false, std::memory_order_release);
    }
    for (SurfaceEdit& e : editsTaken_) {
        if (e.next) {
            // A spray whose map the edit replaces ends here, as one undo step before the edit's.
            if (e.restore || !e.keepMaps) airbrush(false, simTime);
            if (!e.restore) e.next->continueFrom(*surface_, e.keepMaps);
            surface_ = std::move(e.next);
            liveSurface_.store(surface_.get(), std::memory_order_release);
        }
        if (e.keepShape) {
            surface_->relax();
            surface_->wake();
        }
        pushStroke(simTime, AirbrushSettings::Map::Off, e.id);
    }
    const bool any = !editsTaken_.empty();
    editsTaken_.clear();  // the replaced surfaces are freed here, on the simulation thread
    if (any) {  // shown at once, even if the surface it left is at rest and takes no step
        poles_.back() = surface_->poles();
        poles_.publish();
    }
    return any;
}

void HapticRuntime::airbrush(bool spraying, double simTime) {
    using Map = AirbrushSettings::Map;
    const Map want = spraying ? airbrush_.map : Map::Off;
    if (sprayMap_ != Map::Off && want != sprayMap_) {  // released, switched off or to another map
        pushStroke(simTime, sprayMap_);
        sprayMap_ = Map::Off;
    }
    spraying_.store(want != Map::Off, std::memory_order_relaxed);
    if (want == Map::Off) return;
    MaterialMap& m = mapOf(want);
    if (sprayMap_ == Map::Off) {
        sprayMap_ = want;
        // One target for the whole spray, so dabs saturate at it instead of compounding.
        sprayTarget_ = std::clamp(airbrush_.factor * m.mean(), want == Map::Damping || want == Map::Bending || want == Map::Pull ? 0.0 : kMinMaterial, kMaxMaterial);
        nextDab_ = simTime;
    }
    if (simTime < nextDab_) return;
    nextDab_ = std::max(nextDab_ + 1.0 / airbrush_.rate, simTime);  // no burst after a dropped backlog
    // Map coordinates of the mass point nearest the cursor, as the lumped masses sample the maps.
    const int i = surface_->nearestMeshIndex(surface_->cursor().position);
    const int g = surface_->g(), h = surface_->h();
    m.dab(static_cast<double>(i / h) / (g - 1), static_cast<double>(i % h) / (h - 1), airbrush_.radius, sprayTarget_,
          Falloff::Spherical, airbrush_.strength);
    paintedDirty_ = true;
}

void HapticRuntime::pushStroke(double simTime, AirbrushSettings::Map painted, std::uint64_t edit) {
    const std::uint64_t head = strokeHead_.load(std::memory_order_relaxed);
    // A full queue (nobody collecting) merges this stroke into the next one; an edit's event waits
    // for a free slot, since its configuration is only in the event.
    while (edit != 0 && head - strokeTail_.load(std::memory_order_acquire) >= kStrokeSlots &&
           !stopRequested_.load(std::memory_order_acquire))
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (head - strokeTail_.load(std::memory_order_acquire) < kStrokeSlots) {
        StrokeSnapshot& s = strokes_[head % kStrokeSlots];
        s.time = simTime;
        s.step = simSteps_.load(std::memory_order_relaxed);
        s.poles = surface_->poles();
        s.velocities = surface_->velocities();
        const auto& rest = static_cast<const DynamicSurface&>(*surface_).springs().rest();
        std::copy(rest.begin(), rest.end(), s.restLengths.begin());
        s.bendingReference = surface_->bending().reference();  // (same size: no allocation)
        s.painted = painted;
        s.edit = edit;
        // (copying a map allocates only when its size changed: at a spray's end or an edit, not a step)
        for (size_t k = 0; k < kMaps.size(); ++k) {
            if (edit == 0 && kMaps[k] != painted) continue;
            const MaterialMap& m = mapOf(kMaps[k]);
            s.maps[k].rows = m.rows();
            s.maps[k].cols = m.cols();
            s.maps[k].values = m.values();
        }
        strokeHead_.store(head + 1, std::memory_order_release);
    }
    if (edit == 0) strokeCount_.fetch_add(1, std::memory_order_relaxed);
}

void HapticRuntime::fail(const char* message) {
    bool expected = false;
    if (failed_.compare_exchange_strong(expected, true)) {
        std::strncpy(error_.data(), message, error_.size() - 1);
        stopRequested_.store(true, std::memory_order_release);
    }
}

void HapticRuntime::start() {
    if (started_) throw std::runtime_error("session: already started");
    const Points& p = surface_->poles();
    poles_.forEachSlot([&](Points& s) { s = p; });
    for (auto& s : strokes_) {
        s.poles = p;
        s.velocities = surface_->velocities();
        s.restLengths = static_cast<const DynamicSurface&>(*surface_).springs().rest();
        s.bendingReference = surface_->bending().reference();
    }
    if (settings_.logSeconds > 0) {
        ticks_.resize(static_cast<size_t>(settings_.logSeconds * settings_.hapticRate) + 16);
        snapshots_.resize(static_cast<size_t>(settings_.logSeconds / settings_.simDt) + 16);
    }
    // Factor and bound before the clock starts: at 32x32 controls that takes tens of milliseconds,
    // which the first steps would otherwise fall behind the device by. A configuration the core
    // refuses is left for the first step to report, as it always was.
    try {
        prepareSteps(*surface_);
    } catch (const std::exception&) {
    }
    device_->start();
    applyDeviceLimits();
    t0_ = Clock::now();
    started_ = true;
    sim_ = std::thread([this] { simLoop(); });
    haptic_ = std::thread([this] { hapticLoop(); });
}

void HapticRuntime::stop() {
    if (!started_ || joined_) return;
    stopRequested_.store(true, std::memory_order_release);
    if (haptic_.joinable()) haptic_.join();  // it writes a zero force on its way out
    if (sim_.joinable()) sim_.join();
    stoppedAt_.store(now(), std::memory_order_relaxed);
    device_->setForce(Vec3::Zero());
    device_->stop();
    joined_ = true;
    ticks_.resize(tickCount_);
    snapshots_.resize(snapshotCount_);
}

void HapticRuntime::takeRealtimePriority(const std::string& wakeups) {
    const PriorityGrant g = takeHapticPriority(settings_.realtime);
    realtimeHow_ = wakeups.empty() ? g.how : g.how + "; " + wakeups;
    realtimeOk_.store(g.ok, std::memory_order_relaxed);
    realtimeKnown_.store(true, std::memory_order_release);
}

std::string HapticRuntime::realtimeHow() const {
    return realtimeKnown_.load(std::memory_order_acquire) ? realtimeHow_ : std::string();
}

void HapticRuntime::hapticLoop() {
    const PreciseWakeups wakeups;
    takeRealtimePriority(wakeups.how());
    const auto spin = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(settings_.spin));
    const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / settings_.hapticRate));
    const auto idlePeriod = settings_.idleRate > 0
        ? std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / settings_.idleRate)) : period;
    auto next = t0_;
    auto last = t0_;
    bool first = true;
    DeviceSample sample;
    const HapticEstimate none{};  // before the first snapshot: no force (value-initialised: Eigen members zero)
    try {
        bool idle = false, wasIdle = false;
        while (!stopRequested_.load(std::memory_order_acquire)) {
            // Idle (surface at rest, nothing grabbed): poll the device at idleRate only; a grab is
            // seen within 1/idleRate and the next tick is back at full rate.
            next += idle ? idlePeriod : period;
            if (spin.count() > 0 && !idle) {
                wakeups.sleepUntil(next - spin);
                while (Clock::now() < next) {
                }
            } else {
                wakeups.sleepUntil(next);
            }
            const auto tick = Clock::now();
            if (!first && !idle && !wasIdle) {
                const double p = std::chrono::duration<double>(tick - last).count();
                const int bin = std::min(kBins, static_cast<int>(p / kBinWidth));
                periodBins_[bin].fetch_add(1, std::memory_order_relaxed);
                atomicMax(periodMax_, p);
            }
            first = false;
            wasIdle = idle;
            last = tick;
            if (tick - next > 20 * period) next = tick;  // after a long stall, do not burst to catch up
            const double t = std::chrono::duration<double>(tick - t0_).count();
            if (!device_->sample(t, sample)) {
                fail("device lost");
                break;
            }
            if (finiteSample(sample)) cursor_.push(t, sample);
            idle = settings_.idleRate > 0 && simIdle_.load(std::memory_order_relaxed) && !(sample.buttons & 1u);
            estimate_.update();
            const HapticEstimate& e = estimate_.front().sequence ? estimate_.front() : none;
            const Vec3 estimated = finiteSample(sample) ? estimateForce(e, sample.position, sample.orientation, t) : Vec3::Zero();
            const Vec3 rendered = e.sequence ? limitForce(e, estimated, t, limits_) : Vec3::Zero();
            device_->setForce(rendered);
            const double latency = std::chrono::duration<double>(Clock::now() - tick).count();
            latencyBins_[std::min(kBins, static_cast<int>(latency / kBinWidth))].fetch_add(1, std::memory_order_relaxed);
            for (int i = 0; i < 3; ++i) force_[i].store(rendered[i], std::memory_order_relaxed);
            estimateAge_.store(t - e.time, std::memory_order_relaxed);
            if (tickCount_ < ticks_.size()) ticks_[tickCount_++] = {t, sample, estimated, rendered, e.time};
            if (finiteSample(sample)) {
                ShownCursor shown;
                shown.cursor = sample;
                shown.contactValid = e.kind != EstimateKind::None && e.points > 0;
                if (shown.contactValid) shown.contact = e.x[0];
                shown_.write(shown);
            }
            hapticTicks_.fetch_add(1, std::memory_order_relaxed);
            if (settings_.stopWhenFinished && device_->finished(t)) {
                stopRequested_.store(true, std::memory_order_release);
                break;
            }
        }
    } catch (const std::exception& ex) {
        fail(ex.what());
    } catch (...) {
        fail("unknown error in the haptic loop");
    }
    device_->setForce(Vec3::Zero());
    for (auto& f : force_) f.store(0.0, std::memory_order_relaxed);
}

void HapticRuntime::simLoop() {
    lowerThreadPriority(settings_.simNice);
    const double dt = settings_.simDt;
    const double graphicsEvery = settings_.graphicsRate > 0 ? 1.0 / settings_.graphicsRate : INFINITY;
    double simTime = 0, nextGraphics = 0;
    bool grabbed = surface_->tool().grabbed(), button = false;
    const auto idleLook = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(settings_.idleRate > 0 ? 2.0 / settings_.idleRate : 0.005));
    HapticEstimate previous, current;
    Reaction reaction;
    std::uint64_t sequence = 0;
    bool doubleSteps = settings_.catchUp;
    DeviceSample grabbedWhileIdle;  // (the sample a grab began with while the loop idled)
    bool woken = false;
    try {
        while (!stopRequested_.load(std::memory_order_acquire)) {
            // Keep pace with real time: step when the interval it represents has passed.
            double wall = now();
            if (wall < simTime + dt) {
                std::this_thread::sleep_until(t0_ + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(simTime + dt)));
                continue;
            }
            // Behind real time by more than a step: degrade on purpose, one step of twice the
            // length (half the steps per simulated second, each as costly), and simulated time
            // keeps pace with the device instead of running in slow motion. Only past maxLag (a
            // stall) is the backlog dropped.
            const bool doubled = doubleSteps && wall - simTime > 2 * dt;
            const double h = doubled ? 2 * dt : dt;
            if (wall - simTime > settings_.maxLag) {
                const double drop = wall - simTime - h;
                droppedSimTime_.store(droppedSimTime_.load(std::memory_order_relaxed) + drop, std::memory_order_relaxed);
                simTime += drop;
            }
            // The hand where it was at the step's end (cursor_history.hpp), not where it is now.
            DeviceSample hand = grabbedWhileIdle;
            const bool read = woken || cursor_.at(simTime + h, hand);
            const bool fresh = read && !sameSample(hand, taken_);
            woken = false;
            if (fresh) {
                taken_ = hand;
                button = (hand.buttons & 1u) != 0;
            }
            const bool airbrushTaken = airbrushChanged_.exchange(false, std::memory_order_acq_rel);
            if (airbrushTaken) {
                std::lock_guard<std::mutex> lock(airbrushMutex_);
                airbrush_ = airbrushPending_;
            }
            const bool edited = editsQueued_.load(std::memory_order_acquire) && takeEdits(simTime);
            const bool painting = airbrush_.map != AirbrushSettings::Map::Off;
            if (surface_->asleep() && !surface_->tool().grabbed() && !(fresh && button) &&
                sprayMap_ == AirbrushSettings::Map::Off) {
                // At rest and nobody grabbing: nothing can move, so idle (the haptic loop keeps
                // reading the device, at idleRate) and look again two of its samples later: a
                // grab starts within 3/idleRate (30 ms, inside the tool's 50 ms ramp), and each
                // wake costs ~50 us of CPU on a virtual machine; simulated time follows the clock.
                // A grab that began meanwhile starts where the button went down, not where the
                // hand is now: its first step takes that sample.
                simIdle_.store(true, std::memory_order_relaxed);
                const double seen = simTime + h;
                std::this_thread::sleep_for(idleLook);
                woken = cursor_.firstGrabAfter(seen, grabbedWhileIdle);
                simTime = std::max(simTime, now() - dt);
                continue;
            }
            simIdle_.store(false, std::memory_order_relaxed);
            if (fresh || airbrushTaken || edited) {
                const DeviceSample& s = taken_;
                Cursor c;
                c.position = s.position;
                c.orientation = s.orientation;
                c.grab = button && !painting;  // the airbrush takes the button: the tool lets go
                surface_->setCursor(c);
            }
            StepReport r;
            try {
                r = surface_->step(h);
            } catch (const std::invalid_argument&) {
                if (!doubled) throw;
                doubleSteps = false;  // too long a step for this surface: drop backlogs instead
                r = surface_->step(dt);
            }
            const double taken = doubled && doubleSteps ? h : dt;
            simTime += taken;
            simSteps_.fetch_add(1, std::memory_order_relaxed);
            if (taken > dt) doubledSteps_.fetch_add(1, std::memory_order_relaxed);
            if (r.refused) refused_.fetch_add(1, std::memory_order_relaxed);
            if (!r.slept) reaction = r.reaction;
            // Publish the tool's local model, velocities by finite differences over this step.
            surface_->describeTool(reaction, current);
            followEstimate(previous, current, simTime, ++sequence, taken);
            estimate_.write(current);
            if (snapshotCount_ < snapshots_.size()) snapshots_[snapshotCount_++] = current;
            previous = current;
            // Stroke ends: a release edge hands the state over for one undo transaction.
            const bool nowGrabbed = surface_->tool().grabbed();
            if (grabbed && !nowGrabbed) pushStroke(simTime, AirbrushSettings::Map::Off);
            airbrush(button && painting, simTime);
            grabbed = nowGrabbed;
            if (simTime >= nextGraphics) {
                poles_.back() = surface_->poles();
                poles_.publish();
                if (paintedDirty_ && sprayMap_ != AirbrushSettings::Map::Off) {
                    PaintedMap& p = painted_.back();
                    const MaterialMap& m = mapOf(sprayMap_);
                    p.map = sprayMap_;
                    p.rows = m.rows();
                    p.cols = m.cols();
                    p.values = m.values();  // allocates only when the map's size changed
                    painted_.publish();
                    paintedDirty_ = false;
                }
                nextGraphics = simTime + graphicsEvery;
            }
        }
        airbrush(false, simTime);  // a spray under way at the stop is still one undo step
    } catch (const std::exception& ex) {
        fail(ex.what());
    } catch (...) {
        fail("unknown error in the simulation loop");
    }
}

bool HapticRuntime::takePoles(Points& out) {
    if (!poles_.update()) return false;
    out = poles_.front();
    return true;
}

bool HapticRuntime::takeStroke(StrokeSnapshot& out) {
    const std::uint64_t tail = strokeTail_.load(std::memory_order_relaxed);
    if (tail == strokeHead_.load(std::memory_order_acquire)) return false;
    out = strokes_[tail % kStrokeSlots];
    strokeTail_.store(tail + 1, std::memory_order_release);
    return true;
}

RuntimeStatus HapticRuntime::status() const {
    RuntimeStatus s;
    s.running = running();
    s.elapsed = started_ ? (joined_ ? stoppedAt_.load(std::memory_order_relaxed) : now()) : 0.0;
    s.hapticTicks = hapticTicks_.load(std::memory_order_relaxed);
    s.simSteps = simSteps_.load(std::memory_order_relaxed);
    s.refusedSteps = refused_.load(std::memory_order_relaxed);
    s.strokes = strokeCount_.load(std::memory_order_relaxed);
    s.droppedSimTime = droppedSimTime_.load(std::memory_order_relaxed);
    s.doubledSteps = doubledSteps_.load(std::memory_order_relaxed);
    shown_.update();
    const ShownCursor& shown = shown_.front();
    s.cursor = shown.cursor.position;
    s.orientation = shown.cursor.orientation;
    s.grab = (shown.cursor.buttons & 1u) != 0;
    s.contactValid = shown.contactValid;
    s.contact = shown.contact;
    s.spraying = spraying_.load(std::memory_order_relaxed);
    if (s.elapsed > 0) {
        s.hapticHz = static_cast<double>(s.hapticTicks) / s.elapsed;
        s.simHz = static_cast<double>(s.simSteps) / s.elapsed;
    }
    s.periodP50 = binPercentile(periodBins_.get(), kBins, kBinWidth, 0.5);
    s.periodP99 = binPercentile(periodBins_.get(), kBins, kBinWidth, 0.99);
    s.latencyP50 = binPercentile(latencyBins_.get(), kBins, kBinWidth, 0.5);
    s.latencyP99 = binPercentile(latencyBins_.get(), kBins, kBinWidth, 0.99);
    s.periodMax = periodMax_.load(std::memory_order_relaxed);
    s.force = Vec3(force_[0].load(std::memory_order_relaxed), force_[1].load(std::memory_order_relaxed),
                   force_[2].load(std::memory_order_relaxed));
    s.estimateAge = estimateAge_.load(std::memory_order_relaxed);
    if (realtimeKnown_.load(std::memory_order_acquire)) s.realtimePriority = realtimeOk_.load(std::memory_order_relaxed);
    if (failed_.load(std::memory_order_acquire)) s.error = error_.data();
    return s;
}

std::vector<double> HapticRuntime::forceErrors(double floor) const {
    if (!joined_) throw std::runtime_error("session: stop it before analysing its logs");
    std::vector<double> exactMag(ticks_.size(), 0.0), err(ticks_.size(), 0.0);
    std::vector<char> ok(ticks_.size(), 0);
    double largest = 0;
    size_t j = 0;
    for (size_t i = 0; i < ticks_.size(); ++i) {
        const HapticTick& k = ticks_[i];
        while (j + 1 < snapshots_.size() && snapshots_[j + 1].time <= k.t) ++j;
        if (j + 1 >= snapshots_.size() || snapshots_[j].time > k.t) continue;  // no later snapshot to compare with
        const HapticEstimate& a = snapshots_[j];
        const HapticEstimate& b = snapshots_[j + 1];
        if (a.kind != b.kind || a.kind == EstimateKind::None || !k.cursor.valid) continue;
        const double s = (k.t - a.time) / (b.time - a.time);
        const Vec3 exact = estimateForce(blendEstimates(a, b, s), k.cursor.position, k.cursor.orientation, k.t);
        exactMag[i] = exact.norm();
        err[i] = (k.estimated - exact).norm();
        ok[i] = 1;
        largest = std::max(largest, exactMag[i]);
    }
    std::vector<double> out;
    out.reserve(ticks_.size());
    for (size_t i = 0; i < ticks_.size(); ++i)
        if (ok[i]) out.push_back(err[i] / std::max(exactMag[i], floor * largest));
    return out;
}

}  // namespace hs
