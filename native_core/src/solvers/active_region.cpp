#include "solvers/active_region.hpp"

#include <algorithm>

namespace hs {

void RegionChooser::setWhole(const SamplingOperator& A) {
    const int nu = A.nu(), nv = A.nv();
    const GridRect poles = GridRect::whole(nu, nv), mesh = GridRect::whole(A.g(), A.h());
    if (!region_.whole || region_.poles != poles) ++region_.serial;
    region_ = {true, poles, mesh, mesh, region_.serial};
    grown_ = false;
}

bool RegionChooser::choose(const SamplingOperator& A, const RegionSettings& settings, bool allowed, bool toolKnown,
                           const GridRect& toolMesh, const Points& v, double floorSpeed, const Points* force,
                           double floorForce) {
    const std::uint64_t before = region_.serial;
    const bool afresh = wholeNext_;
    wholeNext_ = false;
    if (!settings.enabled || !allowed || !toolKnown || !A.separable() || (afresh && !force)) {
        setWhole(A);
        return region_.serial != before;
    }
    const int nu = A.nu(), nv = A.nv();
    if (afresh) setWhole(A);
    // The moving poles, among those that could move (the region's; every pole after a whole step
    // or an edit), and after an edit the poles out of balance.
    const GridRect searched = region_.poles;
    double fastest = 0;
    searched.forRuns([&](Eigen::Index first, Eigen::Index n) {
        fastest = std::max(fastest, v.middleRows(first, n).cwiseAbs().maxCoeff());
    });
    // Out of a whole step, every pole faster than the sleep test's floor stays in: a region drops
    // only poles at rest, never motion (growing, it adds poles the region held at rest).
    const double moving = region_.whole ? floorSpeed : std::max(floorSpeed, settings.wake * fastest);
    GridRect want{nu, 0, nv, 0, nv};
    const auto include = [&](int i0, int i1, int j0, int j1) {
        want.r0 = std::min(want.r0, i0); want.r1 = std::max(want.r1, i1);
        want.c0 = std::min(want.c0, j0); want.c1 = std::max(want.c1, j1);
    };
    for (int i = searched.r0; i < searched.r1; ++i)
        for (int j = searched.c0; j < searched.c1; ++j)
            if (v.row(static_cast<Eigen::Index>(i) * nv + j).cwiseAbs().maxCoeff() > moving) include(i, i + 1, j, j + 1);
    if (afresh) {
        const double strongest = force->cwiseAbs().maxCoeff();
        const double pushed = std::max(floorForce, settings.wake * strongest);
        for (Eigen::Index k = 0; k < force->rows(); ++k)
            if (force->row(k).cwiseAbs().maxCoeff() > pushed) {
                const int i = static_cast<int>(k / nv), j = static_cast<int>(k % nv);
                include(i, i + 1, j, j + 1);
            }
    }
    if (!toolMesh.empty()) {
        const GridRect p = A.polesOf(toolMesh);
        include(p.r0, p.r1, p.c0, p.c1);
    }
    if (want.empty()) {  // nothing moves and no tool: the surface is settling; keep what there is
        if (!region_.whole) return false;
        setWhole(A);
        return region_.serial != before;
    }
    // The margin, out to whole tiles, and (while awake) never smaller than before.
    const int t = RegionSettings::kTile;
    want = want.grown(settings.margin, nu);
    want.r0 = want.r0 / t * t; want.c0 = want.c0 / t * t;
    want.r1 = std::min(nu, (want.r1 + t - 1) / t * t); want.c1 = std::min(nv, (want.c1 + t - 1) / t * t);
    if (grown_ && !region_.whole)
        want = {std::min(want.r0, region_.poles.r0), std::max(want.r1, region_.poles.r1),
                std::min(want.c0, region_.poles.c0), std::max(want.c1, region_.poles.c1), nv};
    if (static_cast<double>(want.count()) > RegionSettings::kWholeFraction * nu * nv) {
        setWhole(A);
        return region_.serial != before;
    }
    grown_ = true;
    if (!region_.whole && region_.poles == want) return false;
    const GridRect mesh = A.meshOf(want);
    region_ = {false, want, mesh, mesh.grown(2, A.g()), region_.serial + 1};
    return true;
}

}  // namespace hs
