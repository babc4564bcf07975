#include <gtest/gtest.h>
#include "dynamic_surface.hpp"
TEST(Smoke, Steps) {
    hs::DynamicSurface s(hs::BSplineSurface::plane(8, 8, 3, 3, 100, 100), 40, 40);
    for (int i = 0; i < 10; ++i) s.step(1e-3);
}
