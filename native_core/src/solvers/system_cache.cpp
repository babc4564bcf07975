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

}  // namespace hs
