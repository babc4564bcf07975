// The passivity bound is real: a device (mass, damping) against a sampled spring at the bound
// loses energy, at twice the bound it gains it without limit; for the emulated Falcon and at the
// haptic rates the runtime offers.
#include <gtest/gtest.h>

#include <stdexcept>

#include "devices/device_limits.hpp"
#include "devices/passivity.hpp"

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

TEST(Passivity, EachDeviceInTheTableAtItsRenderedStiffness) {
    // What each device gets (device_limits.hpp): at its bound, and with virtual damping taking a
    // share, the wall takes energy out; at twice the bound it puts energy in.
    for (const DeviceLimits& row : deviceLimitsTable())
        for (double rate : row.servoRates) {
            const double T = 1.0 / rate, k = passiveStiffnessFor(row, rate);
            EXPECT_LT(sampledWallEnergyRatio(row.mass, row.damping, k, 0.0, T, 2.0), 1.0) << row.model << " " << rate;
            const double b = 0.5 * row.damping, kd = passiveStiffnessFor(row, rate, b);
            EXPECT_NEAR(kd, 0.5 * k, 1e-9 * k);
            EXPECT_LT(sampledWallEnergyRatio(row.mass, row.damping, kd, b, T, 2.0), 1.0) << row.model << " " << rate;
            EXPECT_GT(sampledWallEnergyRatio(row.mass, row.damping, 2.0 * k, 0.0, T, 2.0), 1e3) << row.model << " " << rate;
        }
}

TEST(Passivity, UnknownDevicesGetTheSoftestRow) {
    EXPECT_EQ(limitsFor("Touch X").model, "Touch X");
    EXPECT_EQ(limitsFor("touch").model, "Touch");
    EXPECT_EQ(limitsFor("omega.3 left").model, "omega.3");
    EXPECT_EQ(limitsFor("something new").model, "Touch");  // the smallest damping
    EXPECT_THROW(passiveStiffnessFor(limitsFor("Touch"), 0.0), std::invalid_argument);
}
