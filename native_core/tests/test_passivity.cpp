// The passivity bound is real: a device (mass, damping) against a sampled spring at the bound
// loses energy, at twice the bound it gains it without limit; for the emulated Falcon and at the
// haptic rates the runtime offers.
#include <gtest/gtest.h>

#include <stdexcept>

#include "passivity.hpp"

using namespace hs;

TEST(Passivity, TheBoundIsColgateAndSchenkels) {
    EXPECT_DOUBLE_EQ(passiveStiffness(2.0, 0.0, 1e-3), 4000.0);
    EXPECT_DOUBLE_EQ(passiveStiffness(2.0, 0.5, 1e-3), 3000.0);  // virtual damping spends the device's
    EXPECT_DOUBLE_EQ(passiveStiffness(2.0, -0.5, 1e-3), 3000.0);
    EXPECT_DOUBLE_EQ(passiveStiffness(1.0, 2.0, 1e-3), 0.0);
    EXPECT_THROW(passiveStiffness(-1.0, 0.0, 1e-3), std::invalid_argument);
    EXPECT_THROW(passiveStiffness(1.0, 0.0, 0.0), std::invalid_argument);
}

TEST(Passivity, AtTheBoundTheWallTakesEnergyOutAtTwiceItPutsItIn) {
    struct Case { double mass, damping, rate; };
    // the emulated Falcon (0.15 kg, 2 N s/m) at 1 and 4 kHz, a heavier and a lighter mechanism
    for (const Case c : {Case{0.15, 2.0, 1000}, Case{0.15, 2.0, 4000}, Case{0.5, 5.0, 1000}, Case{0.05, 0.5, 1000}}) {
        const double T = 1.0 / c.rate, bound = passiveStiffness(c.damping, 0.0, T);
        EXPECT_LT(sampledWallEnergyRatio(c.mass, c.damping, 0.95 * bound, 0.0, T, 2.0), 1.0) << c.mass << " " << c.rate;
        EXPECT_GT(sampledWallEnergyRatio(c.mass, c.damping, 2.0 * bound, 0.0, T, 2.0), 1e6) << c.mass << " " << c.rate;
    }
}

TEST(Passivity, BadArgumentsAreRefused) {
    EXPECT_THROW(sampledWallEnergyRatio(0.0, 1.0, 10.0, 0.0, 1e-3, 1.0), std::invalid_argument);
    EXPECT_THROW(sampledWallEnergyRatio(1.0, 1.0, 10.0, 0.0, 1e-3, 0.0), std::invalid_argument);
}
