#include "runtime/multirate_replay.hpp"

#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

#include "tools_and_constraints/haptic_estimate.hpp"

namespace hs {
namespace {
// s: the simulated time is a sum of steps, the ticks' a product; within this they are the same
// instant (a state whose interval ends at a tick is that tick's).
constexpr double kClockRounding = 1e-9;
}  // namespace

MultirateTicks replayMultirate(DynamicSurface& surface, Device& device, double seconds, const MultirateSettings& s) {
    if (!(s.hapticRate >= 100 && s.hapticRate <= 4000)) throw std::invalid_argument("haptic_rate: must be between 100 and 4000 Hz");
    if (!(s.simDt > 0) || !(s.stepCost >= 0) || !(s.maxLag > 0) || !(s.latency >= 0) || !(seconds > 0) || !std::isfinite(seconds + s.simDt + s.stepCost + s.maxLag + s.latency))
        throw std::invalid_argument("multirate replay: seconds, sim_dt and max_lag must be finite and > 0, step_cost and latency finite and >= 0");
    const double dt = s.simDt;
    const auto ticks = static_cast<Eigen::Index>(std::floor(seconds * s.hapticRate)) + 1;
    MultirateTicks out;
    out.t.resize(static_cast<size_t>(ticks));
    out.stateTime.resize(static_cast<size_t>(ticks));
    out.cursor = Points::Zero(ticks, 3);
    out.force = Points::Zero(ticks, 3);
    double simTime = 0, free = 0;  // the simulation's time, and the clock when it is next free
    // The states on their way to the haptic loop (a state reaches it `latency` after its step ends).
    std::vector<std::pair<double, HapticEstimate>> queue;
    queue.reserve(static_cast<size_t>(s.latency / dt) + 8);
    HapticEstimate previous, current, published;  // published: the newest state the haptic loop has
    Reaction reaction;
    DeviceSample hand, taken;
    std::uint64_t sequence = 0;
    for (Eigen::Index n = 0; n < ticks; ++n) {
        const double t = static_cast<double>(n) / s.hapticRate;
        for (;;) {  // every state published by t
            // The next step starts when the interval it covers has passed and the simulation is free.
            const double start = std::max(free, simTime + dt);
            if (start + s.stepCost > t + kClockRounding) break;
            const double h = s.catchUp && start - simTime > 2 * dt ? 2 * dt : dt;
            if (start - simTime > s.maxLag) {
                out.droppedSimTime += start - simTime - h;
                simTime = start - h;
            }
            if (device.sample(simTime + h, hand) && !sameSample(hand, taken)) {
                taken = hand;
                Cursor c;
                c.position = hand.position;
                c.orientation = hand.orientation;
                c.grab = (hand.buttons & 1u) != 0;
                surface.setCursor(c);
            }
            const StepReport r = surface.step(h);
            simTime += h;
            free = start + s.stepCost;
            ++out.steps;
            if (h > dt) ++out.doubledSteps;
            if (!r.slept) reaction = r.reaction;
            surface.describeTool(reaction, current);
            followEstimate(previous, current, simTime, ++sequence, h);
            previous = current;
            queue.emplace_back(free + s.latency, current);
        }
        size_t arrived = 0;
        while (arrived < queue.size() && queue[arrived].first <= t + kClockRounding) published = queue[arrived++].second;
        queue.erase(queue.begin(), queue.begin() + static_cast<std::ptrdiff_t>(arrived));
        DeviceSample now;
        const bool ok = device.sample(t, now);
        out.t[static_cast<size_t>(n)] = t;
        out.stateTime[static_cast<size_t>(n)] = published.sequence ? published.time : 0.0;
        if (!ok) continue;
        out.cursor.row(n) = now.position.transpose();
        if (published.sequence)
            out.force.row(n) = estimateForce(published, now.position, now.orientation, t).transpose();
    }
    return out;
}

}  // namespace hs
