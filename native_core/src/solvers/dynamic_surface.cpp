#include "solvers/dynamic_surface.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hs {

DynamicSurface::DynamicSurface(BSplineSurface surface, int g, int h)
    : surface_(std::move(surface)), A_(surface_, g, h), mass_(1.0, "mass"), damping_(1.0, "damping"),
      stiffness_(100.0, "stiffness"), bendingMap_(1.0, "bending") {
    const Eigen::Index S = static_cast<Eigen::Index>(g) * h, N = surface_.poles().rows();
    for (Points* m : {&d_, &dd_, &fext_, &ftool_, &force_, &meshTmp_, &meshTmp2_, &base_, &dPrev_, &av_, &history_.d, &history_.av, &history_.dHat, &yMesh_})
        m->setZero(S, 3);
    for (Points* m : {&v_, &fp_, &explicit_.p0, &explicit_.v0, &explicit_.a0, &backup_.p, &backup_.v, &acc_, &cg_.r, &cg_.z, &cg_.p, &cg_.q, &x_, &implicitTool_.z[0], &implicitTool_.z[1], &history_.p, &history_.v, &history_.xHat, &verlet_.a})
        m->setZero(N, 3);
    m_.setZero(S);
    gamma_.setZero(S);
    verlet_.appliedPoles.reserve(static_cast<size_t>(N));
    verlet_.poleMark.assign(static_cast<size_t>(N), 0);
    damping_.allowZero(true);
    bendingMap_.allowZero(true);
    bendingMap_.setUniform(kDefaultBending);
    A_.apply(surface_.poles(), d_);
    springs_ = SpringMesh(g, h, d_);
    constraints_ = ConstraintSet(g, h);
    size_ = (d_.colwise().maxCoeff() - d_.colwise().minCoeff()).norm();
    if (!(size_ > 0)) size_ = (surface_.poles().colwise().maxCoeff() - surface_.poles().colwise().minCoeff()).norm();
    if (!(size_ > 0)) size_ = 1.0;
    double su = 0, sv = 0;
    for (int i = 0; i < g; ++i)
        for (int j = 0; j < h; ++j) {
            if (i + 1 < g) su += (d_.row((i + 1) * h + j) - d_.row(i * h + j)).norm();
            if (j + 1 < h) sv += (d_.row(i * h + j + 1) - d_.row(i * h + j)).norm();
        }
    spacingU_ = su / ((g - 1) * h);
    spacingV_ = sv / (g * (h - 1));
    bending_ = BendingEnergy(g, h, spacingU_, spacingV_, d_);
    setTool("rope");
    terms_.reserve(64);
    refreshMaterials();
}

void DynamicSurface::setReference(const std::array<double, 3>& r) {
    for (double x : r)
        if (!(x > 0) || !std::isfinite(x)) throw std::invalid_argument("reference: size and spacings must be finite and > 0");
    size_ = r[0];
    spacingU_ = r[1];
    spacingV_ = r[2];
    bending_ = BendingEnergy(g(), h(), spacingU_, spacingV_, bending_.reference());
    materialKey_[3] = ~0ull;  // the operator's scaling changed: its weights again
    touch();
}

void SolverSettings::validate() const {
    requireInRange(iterations, "iterations", 1, 1000);
    if (timeOrder != 1 && timeOrder != 2) throw std::invalid_argument("time_order: 1 (backward Euler) or 2 (BDF2)");
    requireInRange(cgIterations, "cg_iterations", 1, 10000);
    requirePositive(accelerationLimit, "acceleration_limit", true);
    requireInRange(maxHalvings, "max_halvings", 0, 30);
    requirePositive(energyTolerance, "energy_tolerance", true);
}

void DynamicSurface::setSolver(const SolverSettings& s) { configure(solver_, s); }
void DynamicSurface::setSleep(const SleepSettings& s) { configure(sleep_.settings, s); }
void DynamicSurface::setEnergyGuard(const EnergyGuardSettings& s) { configure(guard_.settings, s); }
void DynamicSurface::setPlasticity(const Plasticity& p) { configure(springs_.plasticity, p); }
void DynamicSurface::setStiffnessLaw(const ResponseLaw& law) { configure(springs_.law, law); }
void DynamicSurface::setDampingLaw(const ResponseLaw& law) { configure(dampingLaw_, law); }

double DynamicSurface::meshCurvature(int index, int direction) const {
    requireInRange(index, "index", 0, g() * h() - 1);
    const int i = index / h(), j = index % h();
    if (i < 1 || j < 1 || i > g() - 2 || j > h() - 2) throw std::invalid_argument("index: must be an interior point");
    if (direction != 0 && direction != 1) throw std::invalid_argument("direction: 0 (u) or 1 (v)");
    return constraints_.meshCurvature(d_, index, direction);
}

const Points& DynamicSurface::meshVelocities() {
    A_.apply(v_, dd_);
    return dd_;
}

void DynamicSurface::setPoles(const Points& poles) {
    if (poles.rows() != surface_.poles().rows()) throw std::invalid_argument("poles: wrong number of rows");
    if (!withinRange(poles)) throw std::invalid_argument("poles: must be finite and within +-1e9");
    surface_.mutablePoles() = poles;
    v_.setZero();
    if (!mirror_.empty()) mirror_.project(surface_.mutablePoles(), v_);
    held_.capture(surface_.poles());
    held_.snap(surface_.mutablePoles(), v_);  // (the linked poles onto their masters)
    avValid_ = history_.valid = false;
    A_.apply(surface_.poles(), d_);
    touch();
    resetEnergyCeiling();
}

void DynamicSurface::continueFrom(DynamicSurface& live, bool keepMaps) {
    if (live.g() != g() || live.h() != h() || live.poles().rows() != poles().rows())
        throw std::invalid_argument("edit: the edited surface has another sampling or control net than the live one");
    setPoles(live.poles());
    setVelocities(live.velocities());
    springs_.setRest(live.springs_.rest());
    bending_.setReference(live.bending_.reference());
    if (keepMaps) {
        for (auto [mine, theirs] : {std::pair{&mass_, &live.mass_}, {&damping_, &live.damping_}, {&stiffness_, &live.stiffness_},
                                    {&bendingMap_, &live.bendingMap_}})
            if (mine->rows() != theirs->rows() || mine->cols() != theirs->cols() || mine->values() != theirs->values())
                mine->setValues(theirs->rows(), theirs->cols(), theirs->values());
    }
    if (std::string(tool_->name()) == live.tool_->name()) {
        live.tool_->copySettings(*tool_);
        std::swap(tool_, live.tool_);
    }
    cursor_ = live.cursor_;
    // The BDF2 history carries over, so the step after an edit stays second order.
    history_.p = live.history_.p;
    history_.v = live.history_.v;
    history_.d = live.history_.d;
    history_.av = live.history_.av;
    history_.dt = live.history_.dt;
    history_.valid = live.history_.valid;
    time_ = live.time_;
    work_ = live.work_;
    steps_ = live.steps_;
    touch();
}

void DynamicSurface::holdPoles(const std::vector<int>& indices, const std::vector<PoleLink>& links) {
    std::vector<int> sorted = indices;
    std::sort(sorted.begin(), sorted.end());
    mirror_.requireSymmetric(sorted);
    held_.set(indices, links, surface_.mutablePoles());
    held_.expand(v_);
    A_.apply(surface_.poles(), d_);
    avValid_ = history_.valid = false;
    accelerationValid_ = verlet_.valid = false;
    wake();
}

void DynamicSurface::setSymmetry(int direction, const Vec3& point, const Vec3& normal) {
    if (direction == -1) {
        mirror_.clear();
    } else {
        mirror_.set(direction, point, normal, surface_, g(), h(), held_.indices());
        mirror_.project(surface_.mutablePoles(), v_);
        held_.capture(surface_.poles());
        A_.apply(surface_.poles(), d_);
    }
    clearForces();
    avValid_ = history_.valid = false;
    accelerationValid_ = verlet_.valid = false;
    wake();
}

void DynamicSurface::setVelocities(const Points& v) {
    if (v.rows() != v_.rows()) throw std::invalid_argument("velocities: wrong number of rows");
    if (!v.allFinite()) throw std::invalid_argument("velocities: contain NaN or Inf");
    v_ = v;
    held_.expand(v_);
    avValid_ = history_.valid = false;
    touch();
    resetEnergyCeiling();
}

int DynamicSurface::meshIndexAt(double u, double v) const {
    if (!std::isfinite(u) || !std::isfinite(v)) throw std::invalid_argument("uv: must be finite");
    const auto& us = A_.us();
    const auto& vs = A_.vs();
    const double fu = (u - us.front()) / (us.back() - us.front()), fv = (v - vs.front()) / (vs.back() - vs.front());
    if (fu < -1e-12 || fu > 1 + 1e-12 || fv < -1e-12 || fv > 1 + 1e-12)
        throw std::invalid_argument("uv: outside the parametric domain");
    const int a = static_cast<int>(std::lround(std::clamp(fu, 0.0, 1.0) * (g() - 1)));
    const int b = static_cast<int>(std::lround(std::clamp(fv, 0.0, 1.0) * (h() - 1)));
    return a * h() + b;
}

std::pair<double, double> DynamicSurface::meshParameters(int index) const {
    if (index < 0 || index >= g() * h()) throw std::invalid_argument("index: mesh index out of range");
    return {A_.u(index / h()), A_.v(index % h())};
}

void DynamicSurface::refreshMaterials() {
    const std::uint64_t key[4] = {mass_.version(), damping_.version(), stiffness_.version(), bendingMap_.version()};
    if (key[0] == materialKey_[0] && key[1] == materialKey_[1] && key[2] == materialKey_[2] && key[3] == materialKey_[3]) return;
    // Densities per unit parameter area, lumped with trapezoid weights that sum to one.
    const int G = g(), H = h();
    if (bendingRatio_.size() != G * H) bendingRatio_.resize(G * H);  // (once: the mesh does not change)
    for (int a = 0; a < G; ++a)
        for (int b = 0; b < H; ++b) {
            const double w = ((a == 0 || a == G - 1) ? 0.5 : 1.0) / (G - 1) * ((b == 0 || b == H - 1) ? 0.5 : 1.0) / (H - 1);
            const double u = static_cast<double>(a) / (G - 1), v = static_cast<double>(b) / (H - 1);
            m_[a * H + b] = mass_.at(u, v) * w;
            gamma_[a * H + b] = damping_.at(u, v) * w;
            bendingRatio_[a * H + b] = bendingMap_.at(u, v);
        }
    constraints_.setBendingRatio(bendingRatio_);  // curvature constraints beat the plate they bend
    springs_.setStiffness(stiffness_, A_.us(), A_.vs());
    if (key[2] != materialKey_[2] || key[3] != materialKey_[3]) bending_.setWeights(bendingMap_, stiffness_);
    minMass_ = m_.minCoeff();
    maxDampingRate_ = (gamma_.array() / m_.array()).maxCoeff();
    // The stiffest spring, with bending as the spring stiffness of the same Laplacian row sum (16 k).
    maxStiffness_ = stiffness_.values().maxCoeff() + bending_.maxRowSum() / 16;
    for (int i = 0; i < 4; ++i) materialKey_[i] = key[i];
    accelerationValid_ = verlet_.valid = false;
}

void DynamicSurface::ensureMassFactor() {
    // (mass and held-set versions only grow, so their sum changes whenever either does)
    if (massSolver_.ready() && massVersion_ == mass_.version() + held_.version()) return;
    const Eigen::SparseMatrix<double> A = A_.matrix().toEigen();
    massMatrix_ = A.transpose() * m_.asDiagonal() * A;
    held_.restrict(massMatrix_, true);
    massSolver_.factor(massMatrix_, "mass matrix A^T M A");
    massVersion_ = mass_.version() + held_.version();
}

void DynamicSurface::ensureSystem(double dt, bool factor) {
    const std::uint64_t key[5] = {mass_.version(), damping_.version(), stiffness_.version(), structureKey(),
                                  bendingMap_.version()};
    auto current = [&](const SystemSlot& slot) {
        bool same = dt == slot.dt && (slot.factored || !factor);
        for (int i = 0; i < 5; ++i) same = same && key[i] == slot.key[i];
        return same;
    };
    for (std::size_t k = 0; k < systems_.size(); ++k)
        if (current(systems_[k])) {
            system_ = k;
            systems_[k].used = ++systemUses_;
            return;
        }
    // Rebuild the slot used least recently. S = A^T (M + dt D + dt^2 L) A with L the Laplacian of
    // springs and penalty terms and the bending matrix K_b.
    system_ = systems_[0].used <= systems_[1].used ? 0 : 1;
    SystemSlot& slot = systems_[system_];
    slot.used = ++systemUses_;
    Eigen::SparseMatrix<double> D(d_.rows(), d_.rows());
    D = (m_ + dt * gamma_).asDiagonal();
    const Eigen::SparseMatrix<double> Sm = D + (dt * dt) * laplacian();
    const Eigen::SparseMatrix<double> A = A_.matrix().toEigen();
    Eigen::SparseMatrix<double> sys = A.transpose() * Sm * A;
    held_.restrict(sys, true);
    slot.invDiag = sys.diagonal().cwiseInverse();  // Jacobi preconditioner
    if (factor) {
        ensureMassFactor();  // throws first if the mesh does not see every control point
        try {
            slot.solver.factor(sys, "system matrix A^T (M + dt D + dt^2 L) A");
        } catch (const std::runtime_error&) {
            // The mass matrix factors, so only dt^2 L (singular: free translations) can swamp it.
            slot.dt = -1;
            throw std::invalid_argument("dt: too long for this mass and stiffness (dt^2 x stiffness / mass swamps the "
                                        "mass matrix and the system is numerically singular); use a shorter step");
        }
    }
    slot.factored = factor;
    slot.built = ++systemBuilds_;
    slot.dt = dt;
    for (int i = 0; i < 5; ++i) slot.key[i] = key[i];
}

Eigen::SparseMatrix<double> DynamicSurface::laplacian() const {
    std::vector<Eigen::Triplet<double>> t;
    springs_.addLaplacian(t);
    constraints_.addLaplacian(t);
    bending_.addMatrix(t);
    Eigen::SparseMatrix<double> L(d_.rows(), d_.rows());
    L.setFromTriplets(t.begin(), t.end());
    return L;
}

void DynamicSurface::setPointForce(int index, const Vec3& force) {
    if (index < 0 || index >= d_.rows()) throw std::invalid_argument("index: mesh index out of range");
    if (!force.allFinite()) throw std::invalid_argument("force: must be finite");
    const double n = force.norm();
    const Vec3 f = n > maxPointForce ? Vec3(force * (maxPointForce / n)) : force;
    if (mirror_.empty()) fext_.row(index) = f.transpose();
    else mirror_.pointForce(fext_, index, f);
    hasExternal_ = true;
    history_.valid = false;  // the force jumps: BDF2 restarts (see history_.valid)
    touch();
}

void DynamicSurface::clearForces() {
    fext_.setZero();
    hasExternal_ = false;
    history_.valid = false;
    touch();
}

void DynamicSurface::setTool(const std::string& name) {
    auto t = makeTool(name);
    t->reserve(static_cast<size_t>(d_.rows()));
    tool_ = std::move(t);
    touch();
}

void DynamicSurface::setCursor(const Cursor& c) {
    if (!c.position.allFinite() || !c.orientation.coeffs().allFinite())
        throw std::invalid_argument("cursor: position and orientation must be finite");
    if (!(c.orientation.norm() > 0)) throw std::invalid_argument("cursor: orientation must be a non-zero quaternion");
    Cursor n = c;
    n.orientation.normalize();
    if (n.grab && !tool_->grabbed()) {
        tool_->grab(meshView(), n);
        history_.valid = false;
        touch();
    } else if (!n.grab && tool_->grabbed()) {
        tool_->release();
        // Clay keeps what it is given: the stroke's shape becomes what bending measures from.
        // (follow, not setReference: the state is the core's own, finite by its guards, and may lie
        // past the +-1e9 a caller's reference is held to after extreme forces)
        if (springs_.plasticity.enabled) bending_.follow(d_, 1.0);
        history_.valid = false;
        touch();
    }
    cursor_ = n;
}

void DynamicSurface::applyToolForces(double dt, StepReport& r, const Points& at, double phase) {
    if (tool_->grabbed()) {
        ftool_.setZero();
        r.reaction = tool_->apply({at, g(), h(), spacingU_, spacingV_}, cursor_, dt, ftool_, phase);
        if (!mirror_.empty()) mirror_.addMirrored(ftool_);
        toolForces_ = true;
        accelerationValid_ = false;
    } else if (toolForces_) {
        ftool_.setZero();
        toolForces_ = false;
        accelerationValid_ = false;
    }
}

double DynamicSurface::meshForces(const Points& d, const Points& dd, double) {
    force_.setZero();
    const double energy = springs_.addForces(d, force_);
    const bool nonlinearDamping = dampingLaw_.kind != LawKind::Linear;
    if (nonlinearDamping)
        for (Eigen::Index i = 0; i < d.rows(); ++i) meshTmp2_(i, 0) = dampingLaw_.dampingFactor(force_.row(i).norm());
    const double bend = bending_.addForces(d, force_);  // (after the damping law: it reads spring forces)
    if (hasExternal_) force_ += fext_;
    if (toolForces_) force_ += ftool_;
    double penalty = 0;
    if (!constraints_.empty()) penalty = constraints_.addForces(d, force_, terms_);
    if (nonlinearDamping)
        for (Eigen::Index i = 0; i < d.rows(); ++i) force_.row(i) -= gamma_[i] * meshTmp2_(i, 0) * dd.row(i);
    else
        force_ -= gamma_.asDiagonal() * dd;
    return energy + bend + penalty;
}

StepReport DynamicSurface::step(double dt) {
    if (!(dt >= kMinDt) || !std::isfinite(dt)) throw std::invalid_argument("dt: must be finite and >= 1e-9 s");
    refreshMaterials();
    const std::uint64_t key[5] = {mass_.version(), damping_.version(), stiffness_.version(), constraints_.version(),
                                  bendingMap_.version()};
    for (int i = 0; i < 5; ++i)
        if (key[i] != wakeKey_[i]) { touch(); resetEnergyCeiling(); wakeKey_[i] = key[i]; }
    // A held tool keeps the surface awake; its forces are refreshed by applyToolForces each step.
    if (tool_->grabbed()) sleep_.wake();
    StepReport r;
    if (sleep_.asleep()) {
        r.slept = true;
        return r;
    }
    const bool verlet = solver_.kind == IntegratorKind::LocalGlobal && verletStable(dt);
    const bool guard = guardsEnergy(dt, verlet);
    verlet_.stepPotential = -1;
    if (!guard) guard_.reset();
    else guard_.begin([this] { return kineticEnergy() + potentialEnergy(); });
    // Backup for a refused step (separate from the explicit integrator's substep buffers).
    backup_.p = surface_.poles();
    backup_.v = v_;
    const bool tracksWork = hasExternal_ || tool_->grabbed();
    // The mesh before the step: for the work of the applied forces, and for local/global's A v.
    if (tracksWork || solver_.kind == IntegratorKind::LocalGlobal) dPrev_ = d_;
    if (solver_.kind != IntegratorKind::LocalGlobal) avValid_ = history_.valid = false;
    if (!verlet) verlet_.valid = false;
    switch (solver_.kind) {
        case IntegratorKind::Explicit: r = stepExplicit(dt); break;
        case IntegratorKind::ImplicitCG: r = stepImplicitCG(dt); break;
        case IntegratorKind::LocalGlobal: r = verlet ? stepVerlet(dt) : stepLocalGlobal(dt); break;
    }
    if (!surface_.poles().allFinite() || !v_.allFinite()) {
        restoreStepStart(true);
        r.refused = true;
        r.reason = "the step would produce NaN or Inf; state kept (reduce dt or stiffness)";
        return r;
    }
    // Symmetry first: the held set is symmetric, so snapping the held poles back keeps it.
    const bool mirrored = !mirror_.empty() && mirror_.project(surface_.mutablePoles(), v_);
    if ((!held_.empty() && held_.snap(surface_.mutablePoles(), v_)) || mirrored) {
        A_.apply(surface_.poles(), d_);
        avValid_ = false;
    }
    double work = 0;
    if (tracksWork) {
        // Work of the applied forces over the step (forces held over the step), as whole-array
        // products so the loop vectorises.
        if (hasExternal_) work += fext_.cwiseProduct(d_ - dPrev_).sum();
        if (toolForces_) work += ftool_.cwiseProduct(d_ - dPrev_).sum();
    }
    if (guard && !limitEnergy(work, r)) return r;
    work_ += work;
    if (springs_.plasticity.enabled) {
        springs_.applyPlasticity(d_, dt);
        // Between strokes the reference follows plastic flow (under a stroke it holds, so the
        // stroke's shape is fair; the release commits it).
        if (!tool_->grabbed()) bending_.follow(d_, std::min(1.0, springs_.plasticity.rate * dt));
        verlet_.valid = false;  // the rest lengths moved under the forces Verlet carries over
    }
    time_ += dt;
    ++steps_;
    checkSleep(dt);
    return r;
}

void DynamicSurface::prepare(double dt) {
    if (!(dt >= kMinDt) || !std::isfinite(dt)) throw std::invalid_argument("dt: must be finite and >= 1e-9 s");
    refreshMaterials();
    ensureMassFactor();
    if (solver_.kind != IntegratorKind::LocalGlobal) return;
    verletStable(dt);
    ensureSystem(localGlobalH(dt), true);
}

bool DynamicSurface::guardsEnergy(double dt, bool verlet) const {
    if (!guard_.settings.enabled) return false;
    // Verlet is stable here but not a descent method: the guard stays as for every explicit scheme.
    if (verlet) return true;
    // The symmetry's projection is not energy-neutral where something is not symmetric (a penalty
    // constraint on one side, a painted map): the guard takes out what it would put in.
    if (!mirror_.empty()) return true;
    // Point, tangent and normal constraints project onto convex sets, so they keep the guarantee.
    if (solver_.kind != IntegratorKind::LocalGlobal || springs_.law.kind != LawKind::Linear || constraints_.anyNonConvex())
        return true;
    // Local/global's descent guarantee is exact arithmetic's: the solve's rounding grows with the
    // system's stiffness-to-mass ratio (~ dt^2 8 k_max / m_min, Gershgorin), and past 1e8 it can
    // put measurable energy into a resting mesh (seen: 4.5e4 from rest at a ratio of 1e13).
    return dt * dt * 8 * maxStiffness_ > 1e8 * minMass_;
}

bool DynamicSurface::limitEnergy(double work, StepReport& r) {
    // Below this floor energy is rounding noise: 1e-12 of a surface-sized stretch at the mean stiffness.
    const double floor = 1e-12 * stiffness_.mean() * size_ * size_;
    const double ke = kineticEnergy(), pe = verlet_.stepPotential >= 0 ? verlet_.stepPotential : potentialEnergy();
    const EnergyGuard::Verdict verdict = guard_.judge(ke, pe, work, floor);
    if (verdict.kind == EnergyGuard::Verdict::Accept) return true;
    r.energyLimited = true;
    if (verdict.kind == EnergyGuard::Verdict::Scale) {
        v_ *= verdict.scale;
        av_ *= verdict.scale;
        history_.valid = false;
        accelerationValid_ = verlet_.valid = false;
        r.reason = "the step would have created energy; velocities scaled back to the energy ceiling (reduce dt or stiffness)";
        return true;
    }
    restoreStepStart(false);
    r.refused = true;
    r.reason = "the step would have created energy: positions kept, motion stopped (reduce dt or stiffness, or use local_global)";
    return false;
}

void DynamicSurface::checkSleep(double dt) {
    if (!sleep_.watching(tool_->grabbed()) || !sleep_.quietStep(v_.cwiseAbs().maxCoeff(), size_)) return;
    // Net force check, once, at the moment the surface would fall asleep.
    dd_.setZero();
    meshForces(d_, dd_, dt);
    A_.applyTransposed(force_, fp_);
    held_.reduce(fp_);  // (the held poles' reactions are not motion)
    if (sleep_.settle(fp_.cwiseAbs().maxCoeff(), stiffness_.mean() * size_)) {
        v_.setZero();
        avValid_ = history_.valid = verlet_.valid = false;
    }
}

double DynamicSurface::kineticEnergy() {
    refreshMaterials();
    if (!avValid_) A_.apply(v_, dd_);  // local/global and Verlet keep A v
    const double* w = (avValid_ ? av_ : dd_).data();
    double e = 0;
    for (Eigen::Index i = 0; i < m_.size(); ++i) e += m_[i] * (w[3 * i] * w[3 * i] + w[3 * i + 1] * w[3 * i + 1] + w[3 * i + 2] * w[3 * i + 2]);
    return 0.5 * e;
}

void DynamicSurface::restoreStepStart(bool keepVelocity) {
    surface_.mutablePoles() = backup_.p;
    if (keepVelocity) v_ = backup_.v;
    else v_.setZero();
    avValid_ = history_.valid = false;
    A_.apply(surface_.poles(), d_);
    accelerationValid_ = verlet_.valid = false;
}

double DynamicSurface::potentialEnergy() {
    refreshMaterials();
    double e = springs_.energy(d_) + bending_.energy(d_);
    if (!constraints_.empty()) {
        force_.setZero();
        e += constraints_.addForces(d_, force_, terms_);
    }
    return e;
}

const Points& DynamicSurface::potentialGradient() {
    refreshMaterials();
    force_.setZero();
    springs_.addForces(d_, force_);
    bending_.addForces(d_, force_);
    if (!constraints_.empty()) constraints_.addForces(d_, force_, terms_);
    A_.applyTransposed(force_, fp_);
    fp_ = -fp_;
    accelerationValid_ = false;  // fp_ and force_ are the explicit scheme's scratch
    return fp_;
}

Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> DynamicSurface::curvatureGrid() const {
    const auto& ops = A_.derivativeOperators(surface_);
    const Eigen::Index S = d_.rows();
    Points der[5];
    for (int k = 0; k < 5; ++k) {
        der[k].resize(S, 3);
        ops[k].multiply(surface_.poles(), der[k]);
    }
    Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> out(S, 6);
    for (Eigen::Index i = 0; i < S; ++i) {
        SurfaceDerivatives sd;
        sd.s = d_.row(i);
        sd.su = der[0].row(i); sd.sv = der[1].row(i);
        sd.suu = der[2].row(i); sd.suv = der[3].row(i); sd.svv = der[4].row(i);
        const Curvature c = curvatureFrom(sd);
        out.row(i) << c.ku, c.kv, c.kmin, c.kmax, c.mean, c.gauss;
    }
    return out;
}

}  // namespace hs
