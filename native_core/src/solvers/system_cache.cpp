#include "solvers/system_cache.hpp"

namespace hs {

void SystemCache::setMass(Eigen::SparseMatrix<double> m, std::uint64_t version) {
    massMatrix_ = std::move(m);
    massSolver_.factor(massMatrix_, "mass matrix A^T M A");
    massVersion_ = version;
}

bool SystemCache::use(double dt, bool factor, const Key& key) {
    for (std::size_t k = 0; k < slots_.size(); ++k)
        if (dt == slots_[k].dt && (slots_[k].factored || !factor) && key == slots_[k].key) {
            current_ = k;
            slots_[k].used = ++uses_;
            return true;
        }
    return false;
}

SystemCache::Slot& SystemCache::replace() {
    current_ = slots_[0].used <= slots_[1].used ? 0 : 1;
    Slot& slot = slots_[current_];
    slot.used = ++uses_;
    slot.dt = -1;  // (until built(): a build that throws leaves no slot claiming it)
    return slot;
}

void SystemCache::built(double dt, bool factored, const Key& key) {
    Slot& slot = slots_[current_];
    slot.factored = factored;
    slot.built = ++builds_;
    slot.dt = dt;
    slot.key = key;
}

SystemCache::RegionSlot& SystemCache::region(const GridRect& poles) {
    const Slot& full = slots_[current_];
    RegionSlot* slot = &regions_[0];
    for (RegionSlot& r : regions_) {
        if (r.system == full.built && r.poles == poles) {
            r.used = ++uses_;
            return r;
        }
        if (r.used < slot->used) slot = &r;
    }
    // The principal submatrix on the region's poles, numbered row by row of the rectangle.
    const int width = poles.c1 - poles.c0;
    const auto compact = [&](int index) {
        const int i = index / poles.stride, j = index % poles.stride;
        return poles.contains(i, j) ? (i - poles.r0) * width + (j - poles.c0) : -1;
    };
    std::vector<Eigen::Triplet<double>> t;
    poles.forRuns([&](Eigen::Index first, Eigen::Index length) {
        for (Eigen::Index c = first; c < first + length; ++c)
            for (Eigen::SparseMatrix<double>::InnerIterator it(full.matrix, c); it; ++it) {
                const int r = compact(static_cast<int>(it.row()));
                if (r >= 0) t.emplace_back(r, compact(static_cast<int>(c)), it.value());
            }
    });
    const Eigen::Index n = poles.count();
    Eigen::SparseMatrix<double> sub(n, n);
    sub.setFromTriplets(t.begin(), t.end());
    slot->system = 0;  // (until factored: a factorisation that throws leaves no slot claiming it)
    // (a region changes mid-stroke: the dense inverse's O(n^3) would stall the step it changes on,
    // 40 ms at 24 x 24 poles, where the sparse factors take a few)
    slot->solver.factor(sub, "system matrix of the active region", kRegionDenseLimit);
    slot->poles = poles;
    slot->system = full.built;
    slot->built = ++builds_;
    slot->used = ++uses_;
    slot->b.setZero(n, 3);
    slot->x.setZero(n, 3);
    return *slot;
}

}  // namespace hs
