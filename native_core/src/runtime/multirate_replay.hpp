// A session's two rates replayed on a virtual clock (issue 49): the simulation takes steps that each
// cost `stepCost` seconds of the clock, keeping pace as HapticRuntime's simulation thread does (a
// step when the interval it covers has passed, twice simDt when behind, past maxLag the backlog
// dropped; the cursor where the device had it at the step's end), and the haptic loop renders at
// hapticRate from the newest state published by then. Deterministic, so the rendered force can be
// compared tick by tick with the exact one: stepCost 0 publishes every state the instant its
// interval ends, and each tick renders the surface as a simulation at the haptic rate has it.
#pragma once
#include <vector>

#include "devices/device.hpp"
#include "solvers/dynamic_surface.hpp"

namespace hs {

struct MultirateSettings {
    double hapticRate = 1000;  ///< Hz
    double simDt = 1e-3;       ///< s: the simulation's step (twice it when behind, as the runtime)
    double stepCost = 0;       ///< s of the clock one step takes
    double maxLag = 0.01;      ///< s: further behind, the simulation drops the backlog
    bool catchUp = true;       ///< steps of twice simDt when more than a step behind
    /// s from a step's end to its state reaching the haptic loop, beside the step's cost (a
    /// pipelined simulation: the haptic loop's model alone bridges the age, the states are exact)
    double latency = 0;
};

struct MultirateTicks {
    std::vector<double> t;          ///< s: each haptic tick
    std::vector<double> stateTime;  ///< s: simulated time of the state it rendered from
    Points cursor, force;           ///< the cursor, and the estimate's force on it (before the safety layer)
    double droppedSimTime = 0;
    int steps = 0, doubledSteps = 0;
};

/// Plays `device` for `seconds` on `surface` (stepped in place). Throws what a step throws.
MultirateTicks replayMultirate(DynamicSurface& surface, Device& device, double seconds, const MultirateSettings& settings);

}  // namespace hs
