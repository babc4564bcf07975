#include "dynamics/surface_state.hpp"

namespace hs {

SurfaceState::SurfaceState(BSplineSurface s, int g, int h) : surface(std::move(s)), A(surface, g, h) {
    const Eigen::Index S = static_cast<Eigen::Index>(g) * h, N = surface.poles().rows();
    d.setZero(S, 3);
    av.setZero(S, 3);
    meshAtStart.setZero(S, 3);
    for (Points* m : {&v, &polesAtStart, &velocitiesAtStart}) m->setZero(N, 3);
    sampleMesh();
    size = (d.colwise().maxCoeff() - d.colwise().minCoeff()).norm();
    if (!(size > 0)) size = (surface.poles().colwise().maxCoeff() - surface.poles().colwise().minCoeff()).norm();
    if (!(size > 0)) size = 1.0;
    double su = 0, sv = 0;
    for (int i = 0; i < g; ++i)
        for (int j = 0; j < h; ++j) {
            if (i + 1 < g) su += (d.row((i + 1) * h + j) - d.row(i * h + j)).norm();
            if (j + 1 < h) sv += (d.row(i * h + j + 1) - d.row(i * h + j)).norm();
        }
    spacingU = su / ((g - 1) * h);
    spacingV = sv / (g * (h - 1));
}

}  // namespace hs
