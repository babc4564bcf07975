// The energy guard of the non-descent schemes (see EnergyGuardSettings): a ceiling on kinetic plus
// potential energy that starts at the energy when the configuration last changed and grows by the
// positive work of the applied forces.
#pragma once
#include <algorithm>
#include <cmath>

#include "common/types.hpp"

namespace hs {

/// Kinetic plus potential energy may not exceed (1 + slack) times the ceiling.
struct EnergyGuardSettings {
    bool enabled = true;
    double slack = 0.25;
    void validate() const { requirePositive(slack, "energy_slack", true); }
};

class EnergyGuard {
public:
    /// What a step's end state gets: kept, kept with velocities scaled by `scale`, or refused.
    struct Verdict {
        enum Kind { Accept, Scale, Refuse } kind = Accept;
        double scale = 1;
    };

    EnergyGuardSettings settings;

    /// Something outside a step changed the energy: the next guarded step starts a new ceiling.
    void reset() { valid_ = false; }
    /// Something outside a step took energy out (`energy` is what is left): the ceiling comes down
    /// to it, never up (a reset would let each such event raise it by the slack).
    void lower(double energy) {
        if (valid_) ceiling_ = std::min(ceiling_, energy);
    }
    /// Before a step: starts the ceiling at `energy()` if there is none (only called when guarding).
    template <class Energy>
    void begin(Energy&& energy) {
        if (!valid_) {
            ceiling_ = energy();
            valid_ = true;
        }
    }
    /// After a finite step that did `work`, ending at kinetic `ke` and potential `pe` energy;
    /// below `floor` energy is rounding noise. Work done in a refused step was never done: the
    /// ceiling grows only on acceptance.
    Verdict judge(double ke, double pe, double work, double floor) {
        const double ceiling = ceiling_ + std::max(0.0, work);
        if (ke + pe <= (1 + settings.slack) * ceiling + floor) {
            ceiling_ = ceiling;
            return {};
        }
        if (pe <= ceiling && ke > 0) {
            ceiling_ = ceiling;
            return {Verdict::Scale, std::sqrt((ceiling - pe) / ke)};
        }
        return {Verdict::Refuse, 0};
    }
    /// The current ceiling (0 while there is none).
    double ceiling() const { return valid_ ? ceiling_ : 0.0; }

private:
    double ceiling_ = 0;
    bool valid_ = false;
};

}  // namespace hs
