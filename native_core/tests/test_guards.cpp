// The energy guard and the sleep monitor on their own (DynamicSurface's tests cover them in use).
#include <gtest/gtest.h>

#include "dynamics/energy_guard.hpp"
#include "dynamics/sleep_monitor.hpp"

using namespace hs;

TEST(EnergyGuard, AcceptsWithinTheCeilingScalesKineticExcessAndRefusesPotentialExcess) {
    EnergyGuard g;
    g.begin([] { return 10.0; });
    EXPECT_EQ(g.ceiling(), 10.0);
    g.begin([] { return 99.0; });  // a ceiling stays until reset
    EXPECT_EQ(g.ceiling(), 10.0);
    EXPECT_EQ(g.judge(4.0, 8.0, 0.0, 0.0).kind, EnergyGuard::Verdict::Accept);  // 12 <= 1.25 * 10
    EXPECT_EQ(g.judge(4.0, 8.0, 5.0, 0.0).kind, EnergyGuard::Verdict::Accept);  // work raises the ceiling
    EXPECT_EQ(g.ceiling(), 15.0);
    const EnergyGuard::Verdict scaled = g.judge(40.0, 11.0, 0.0, 0.0);
    ASSERT_EQ(scaled.kind, EnergyGuard::Verdict::Scale);
    EXPECT_DOUBLE_EQ(40.0 * scaled.scale * scaled.scale + 11.0, 15.0);  // back to the ceiling
    EXPECT_EQ(g.judge(1.0, 16.0 * 1.25 + 1.0, 0.0, 0.0).kind, EnergyGuard::Verdict::Refuse);
    EXPECT_EQ(g.ceiling(), 15.0);  // work done in a refused step was never done
    g.reset();
    EXPECT_EQ(g.ceiling(), 0.0);
    EXPECT_THROW((EnergyGuardSettings{true, -1.0}.validate()), std::invalid_argument);
}

TEST(SleepMonitor, FallsAsleepAfterQuietStepsWhenTheNetForceIsSmall) {
    SleepMonitor m;
    m.settings.steps = 3;
    m.settings.tolerance = 1e-6;
    EXPECT_FALSE(m.quietStep(0.0, 100.0));
    EXPECT_FALSE(m.quietStep(0.0, 100.0));
    EXPECT_FALSE(m.watching(true));  // a held tool starts the count again
    EXPECT_TRUE(m.watching(false));
    EXPECT_FALSE(m.quietStep(0.0, 100.0));
    EXPECT_FALSE(m.quietStep(1.0, 100.0));  // too fast
    EXPECT_FALSE(m.quietStep(0.0, 100.0));
    EXPECT_FALSE(m.quietStep(0.0, 100.0));
    ASSERT_TRUE(m.quietStep(0.0, 100.0));
    EXPECT_FALSE(m.settle(1.0, 1.0));  // a net force keeps it awake, counting again
    EXPECT_FALSE(m.asleep());
    for (int i = 0; i < 2; ++i) EXPECT_FALSE(m.quietStep(0.0, 100.0));
    ASSERT_TRUE(m.quietStep(0.0, 100.0));
    EXPECT_TRUE(m.settle(1e-9, 1.0));
    EXPECT_TRUE(m.asleep());
    m.wake();
    EXPECT_FALSE(m.asleep());
    EXPECT_THROW((SleepSettings{true, 0.0, 10}.validate()), std::invalid_argument);
}
