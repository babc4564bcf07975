// Paper section 5: haptics at a fixed high rate, simulation as fast as real time allows, graphics
// at up to 60 Hz, weakly synchronised by lock-free triple buffers, so a slow simulation never
// stalls the device. The haptic thread never allocates, locks or touches Python.
#pragma once
#include "common/names.hpp"
#include <array>
#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "devices/device.hpp"
#include "runtime/cursor_history.hpp"
#include "solvers/dynamic_surface.hpp"
#include "tools_and_constraints/haptic_estimate.hpp"
#include "common/triple_buffer.hpp"

namespace hs {

struct RuntimeSettings {
    double hapticRate = kDefaultHapticRate;  ///< Hz, 100 to 4000
    double simDt = 5e-4;        ///< simulation step (s); the simulation keeps pace with real time
    double graphicsRate = 60;   ///< pole snapshots per second for the GUI (0: none)
    double maxForce = 0;        ///< clamp on the rendered force; 0: the device's limit (none if it has none)
    double maxStiffness = 0;    ///< limit on the rendered force-displacement slope; 0: the device's
    double staleLimit = 0.02;   ///< s: a simulation snapshot older than this starts fading the force
    double fadeTime = 0.05;     ///< s: from full force to zero once stale
    double maxLag = 0.01;       ///< s: a simulation further behind real time drops the difference (it
                                ///< runs in slow motion rather than let the estimate extrapolate far)
    /// A simulation more than a step behind real time takes steps of twice simDt until it has
    /// caught up (prepared and factored beforehand), so it keeps pace rather than drop time.
    bool catchUp = true;
    double logSeconds = 0;      ///< > 0: keep every haptic tick and simulation snapshot for analysis
    bool stopWhenFinished = false;  ///< stop when a finite (replay) device has played out
    bool realtime = true;       ///< try SCHED_FIFO for the haptic thread (needs privileges; without them it runs as before)
    /// s before each haptic tick the thread stops sleeping and spins on the clock: a sleeping
    /// thread wakes up to a scheduler's latency late, a spinning one on time (0: sleep only).
    double spin = 0;
    /// Niceness added to the simulation thread (0..19, no privileges needed): the haptic thread
    /// then wins the core from it at once when both are ready.
    int simNice = 0;
    double idleRate = 100;      ///< Hz: device polling while the surface rests and nothing is grabbed (0: never idle)
};

struct RuntimeStatus {
    bool running = false;
    double elapsed = 0;             ///< s since start
    double hapticHz = 0, simHz = 0;
    double periodP50 = 0, periodP99 = 0, periodMax = 0;  ///< haptic period (s)
    double latencyP50 = 0, latencyP99 = 0;  ///< s from reading the device to writing its force
    std::uint64_t hapticTicks = 0, simSteps = 0, refusedSteps = 0, strokes = 0;
    double droppedSimTime = 0;      ///< s of simulated time dropped to keep up with real time
    std::uint64_t doubledSteps = 0; ///< steps of twice simDt taken to catch up with real time
    Vec3 force = Vec3::Zero();      ///< last rendered force
    double estimateAge = 0;         ///< s: age of the snapshot the last tick used
    bool realtimePriority = false;
    std::string error;              ///< why the session stopped by itself ("" if it did not)
    // for the GUI overlay: the last finite cursor and the tool's contact point (rope: the grabbed
    // mesh point), as the haptic loop last saw them
    Vec3 cursor = Vec3::Zero();
    Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
    bool grab = false, contactValid = false;
    Vec3 contact = Vec3::Zero();
    bool spraying = false;          ///< the airbrush is spraying (button held with the airbrush on)
};

/// What the haptic loop shows the GUI each tick (one writer, one reader: status()).
struct ShownCursor {
    DeviceSample cursor;
    bool contactValid = false;
    Vec3 contact = Vec3::Zero();
};

/// One haptic tick, kept when logging.
struct HapticTick {
    double t = 0;
    DeviceSample cursor;
    Vec3 estimated = Vec3::Zero();  ///< the estimate's force before the safety layer
    Vec3 rendered = Vec3::Zero();   ///< what was sent to the device
    double stateTime = 0;           ///< simulated time of the state the estimate came from
};

/// The airbrush during a session. While it is on, the device's first button sprays the map
/// instead of grabbing (the tool lets go and renders no force): a dab every 1/rate seconds at the
/// mass point nearest the cursor moves the map toward `factor` times its mean at the spray's start.
struct AirbrushSettings {
    enum class Map { Off, Mass, Damping, Stiffness, Bending, Pull };
    Map map = Map::Off;
    double radius = 0.08;    ///< in map coordinates (the unit square)
    double factor = 3.0;     ///< target = factor * the map's mean when the spray started
    double strength = 0.25;  ///< per dab, at the centre
    double rate = 30;        ///< dabs per second of simulated time
    /// Throws std::invalid_argument naming the first bad field.
    void validate() const;
};

inline constexpr std::array<Named<AirbrushSettings::Map>, 5> kMapNames{{
    {"mass", AirbrushSettings::Map::Mass}, {"damping", AirbrushSettings::Map::Damping},
    {"stiffness", AirbrushSettings::Map::Stiffness}, {"bending", AirbrushSettings::Map::Bending},
    {"pull", AirbrushSettings::Map::Pull}}};
const char* mapName(AirbrushSettings::Map map);  ///< "mass", "damping", "stiffness", "bending", "pull" ("" when off)
/// The five maps, in the order of StrokeSnapshot::maps.
constexpr std::array<AirbrushSettings::Map, 5> kMaps = {AirbrushSettings::Map::Mass, AirbrushSettings::Map::Damping,
                                                        AirbrushSettings::Map::Stiffness, AirbrushSettings::Map::Bending,
                                                        AirbrushSettings::Map::Pull};

/// A material map's values as a snapshot carries them.
struct MapSnapshot {
    int rows = 1, cols = 1;
    Eigen::VectorXd values;
};

/// An edit made while a session runs, taken up by the simulation thread between two steps.
/// `next` is the surface as the edit leaves it, configured (maps, constraints, tool, laws,
/// plasticity, integrator) and factored on the posting thread, so the simulation only swaps it
/// in: it continues from the live surface (DynamicSurface::continueFrom: motion, plastic flow, the
/// held tool; the live maps too unless the edit changed them). A `restore` (undo, redo) takes
/// `next` as it is instead: its shape, at rest. `keepShape` then makes the current shape the rest
/// shape. Without `next` only `keepShape` applies.
struct SurfaceEdit {
    std::uint64_t id = 0;  ///< > 0, names the edit in its event
    std::shared_ptr<DynamicSurface> next;
    bool restore = false;
    bool keepMaps = true;
    bool keepShape = false;
};

/// Sculpt state at the end of a stroke (a grab released, or a spray ended) or after an edit, for
/// one undo transaction each. A spray also carries the painted map (`painted` names it); an edit
/// (`edit` > 0) carries all three maps.
struct StrokeSnapshot {
    double time = 0;
    std::uint64_t step = 0;  ///< simulation steps taken when it happened
    Points poles, velocities;
    std::vector<double> restLengths;
    Points bendingReference;  ///< the bending energy's reference (clay's follows plastic flow)
    AirbrushSettings::Map painted = AirbrushSettings::Map::Off;
    std::uint64_t edit = 0;
    std::array<MapSnapshot, 5> maps;  ///< in kMaps order (those carried)
};

/// The map a spray is painting, as the GUI shows it while the spray goes on.
struct PaintedMap {
    AirbrushSettings::Map map = AirbrushSettings::Map::Off;
    int rows = 1, cols = 1;
    Eigen::VectorXd values;
};

class HapticRuntime {
public:
    HapticRuntime(std::shared_ptr<DynamicSurface> surface, std::shared_ptr<Device> device, RuntimeSettings settings);
    ~HapticRuntime();
    HapticRuntime(const HapticRuntime&) = delete;
    HapticRuntime& operator=(const HapticRuntime&) = delete;

    void start();
    /// Zeroes the force, then joins both threads. Idempotent.
    void stop();
    /// False once stopped or once a loop asked to stop (error, device lost, replay finished).
    bool running() const { return started_ && !stopRequested_.load(std::memory_order_acquire); }
    /// True before start() and once stop() has joined the threads.
    bool joined() const { return !started_ || joined_; }
    RuntimeStatus status() const;
    /// How the haptic thread got real-time priority ("SCHED_FIFO 49 (rtprio limit)", "SCHED_FIFO 20
    /// from RealtimeKit"), or why it got none ("none: ..."); "off" when not asked; "" until known.
    /// (Apart from status(), which allocates nothing: a caller polling it is not charged a string.)
    std::string realtimeHow() const;

    /// Newest pole snapshot if one arrived since the last call (GUI thread).
    bool takePoles(Points& out);
    /// The map being sprayed, if it changed since the last call (GUI thread; at the graphics rate).
    bool takePaintedMap(PaintedMap& out);
    /// Oldest unclaimed stroke end, if any (session thread).
    bool takeStroke(StrokeSnapshot& out);
    /// Switches the airbrush (any thread); the simulation takes it up before its next step.
    void setAirbrush(const AirbrushSettings& a);
    /// Queues an edit (any thread; see SurfaceEdit): its surface is prepared for the session's
    /// step here, the simulation thread swaps it in between two steps and reports it as an event
    /// (takeStroke, `edit` = its id). The haptic thread never sees the queue. Throws
    /// std::invalid_argument for an edit that cannot apply (another sampling, id 0). Returns the
    /// simulation steps taken when it entered the queue.
    std::uint64_t postEdit(SurfaceEdit edit);
    /// The surface the simulation steps (it changes with each edit); read its state only while
    /// stopped.
    std::shared_ptr<DynamicSurface> surface() const { return surface_; }

    // --- analysis (after stop, with logSeconds > 0) --------------------------------------------
    const std::vector<HapticTick>& ticks() const { return ticks_; }
    const std::vector<HapticEstimate>& snapshots() const { return snapshots_; }
    /// Per tick: |estimated - exact| / max(|exact|, floor * max|exact|), exact from the snapshots
    /// around the tick's time (the surface as the simulation computed it then).
    std::vector<double> forceErrors(double floor = 0.05) const;

    /// The settings in force: limits left at 0 filled in from the device (after start(), from the
    /// device as it found itself on opening).
    const RuntimeSettings& settings() const { return settings_; }

private:
    void hapticLoop();
    /// SCHED_FIFO for the calling (haptic) thread: directly where the rtprio limit allows, else from
    /// RealtimeKit; says how, or why not (realtimeHow()).
    void takeRealtimePriority(const std::string& wakeups);  // (wakeups: how the thread is woken, if worth saying)
    void simLoop();
    double now() const;
    void fail(const char* message);
    /// Simulation thread: sprays while `spraying`, and hands a finished spray over as a stroke.
    void airbrush(bool spraying, double simTime);
    void pushStroke(double simTime, AirbrushSettings::Map painted, std::uint64_t edit = 0);
    /// Simulation thread: applies the queued edits; true if any did (the cursor is set anew).
    bool takeEdits(double simTime);
    MaterialMap& mapOf(AirbrushSettings::Map map);  ///< the surface's map (not Off)

    std::shared_ptr<DynamicSurface> surface_;
    std::shared_ptr<Device> device_;
    RuntimeSettings settings_;
    DeviceCaps caps_;
    ForceLimits limits_;
    std::array<double, 2> requestedLimits_{};  // max force and stiffness as given (0: the device's)
    void applyDeviceLimits();
    void prepareSteps(DynamicSurface& surface) const;
    std::chrono::steady_clock::time_point t0_;
    std::thread haptic_, sim_;
    bool started_ = false, joined_ = false;
    std::atomic<bool> stopRequested_{false};

    CursorHistory cursor_;                  // haptic -> simulation
    TripleBuffer<HapticEstimate> estimate_; // simulation -> haptic
    TripleBuffer<Points> poles_;            // simulation -> GUI
    TripleBuffer<PaintedMap> painted_;      // simulation -> GUI, while spraying
    mutable TripleBuffer<ShownCursor> shown_;  // haptic -> GUI (status(): one reader)

    // GUI -> simulation: the airbrush, taken up between steps (the lock only when it changed).
    std::mutex airbrushMutex_;
    AirbrushSettings airbrushPending_;
    std::atomic<bool> airbrushChanged_{false};
    // GUI -> simulation: edits (the lock only when the flag says the queue is not empty).
    static constexpr size_t kEditSlots = 16;
    std::mutex editMutex_;
    std::vector<SurfaceEdit> editsPending_, editsTaken_;  // swapped, so taking them allocates nothing
    std::atomic<bool> editsQueued_{false};
    std::atomic<const DynamicSurface*> liveSurface_{nullptr};  // which surface steps (postEdit refuses it)
    std::array<int, 3> sampling_{};  // g, h and the pole count every edit must keep
    // simulation thread only
    DeviceSample taken_;  // the cursor the surface was last given
    AirbrushSettings airbrush_;
    AirbrushSettings::Map sprayMap_ = AirbrushSettings::Map::Off;  // the map of the spray under way
    double sprayTarget_ = 0, nextDab_ = 0;
    bool paintedDirty_ = false;  // a dab since the last graphics snapshot
    std::atomic<bool> spraying_{false};  // for status()

    static constexpr int kStrokeSlots = 8;
    std::array<StrokeSnapshot, kStrokeSlots> strokes_;
    std::atomic<std::uint64_t> strokeHead_{0}, strokeTail_{0};

    // statistics (relaxed atomics: read by status() while the loops run)
    static constexpr int kBins = 4000;      // 2.5 us bins up to 10 ms
    static constexpr double kBinWidth = 2.5e-6;
    std::unique_ptr<std::atomic<std::uint32_t>[]> periodBins_, latencyBins_;
    std::atomic<double> periodMax_{0}, estimateAge_{0}, droppedSimTime_{0};
    std::atomic<std::uint64_t> doubledSteps_{0};
    std::atomic<std::uint64_t> hapticTicks_{0}, simSteps_{0}, refused_{0}, strokeCount_{0};
    std::atomic<double> force_[3] = {0.0, 0.0, 0.0};
    std::atomic<double> stoppedAt_{0};
    std::atomic<bool> realtimeOk_{false}, failed_{false}, simIdle_{false};
    std::string realtimeHow_;                 // written once by the haptic thread, then realtimeKnown_
    std::atomic<bool> realtimeKnown_{false};
    std::array<char, 256> error_{};

    std::vector<HapticTick> ticks_;
    std::vector<HapticEstimate> snapshots_;
    size_t tickCount_ = 0, snapshotCount_ = 0;  // owned by their threads until join
};

}  // namespace hs
