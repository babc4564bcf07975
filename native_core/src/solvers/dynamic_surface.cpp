#include "solvers/dynamic_surface.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hs {

DynamicSurface::DynamicSurface(BSplineSurface surface, int g, int h)
    : state_(std::move(surface), g, h), material_(g, h, state_.spacingU, state_.spacingV, state_.d), forces_(g, h),
      scratch_(state_.d.rows(), state_.poles().rows()), explicit_(state_.poles().rows()), cg_(state_.poles().rows()),
      localGlobal_(state_.d.rows(), state_.poles().rows()), verlet_(state_.poles().rows()) {
    refreshMaterials();
}

void DynamicSurface::setReference(const std::array<double, 3>& r) {
    for (double x : r)
        if (!(x > 0) || !std::isfinite(x)) throw std::invalid_argument("reference: size and spacings must be finite and > 0");
    state_.size = r[0];
    state_.spacingU = r[1];
    state_.spacingV = r[2];
    material_.rescale(g(), h(), state_.spacingU, state_.spacingV);
    touch();
}

void SolverSettings::validate() const {
    requireInRange(iterations, "iterations", 1, 1000);
    if (timeOrder != 1 && timeOrder != 2) throw std::invalid_argument("time_order: 1 (backward Euler) or 2 (BDF2)");
    requireInRange(cgIterations, "cg_iterations", 1, 10000);
    requirePositive(accelerationLimit, "acceleration_limit", true);
    requireInRange(maxHalvings, "max_halvings", 0, 30);
    requirePositive(energyTolerance, "energy_tolerance", true);
    region.validate();
}

void DynamicSurface::setSolver(const SolverSettings& s) { configure(solver_, s); }
void DynamicSurface::setSleep(const SleepSettings& s) { configure(sleep_.settings, s); }
void DynamicSurface::setEnergyGuard(const EnergyGuardSettings& s) { configure(guard_.settings, s); }
void DynamicSurface::setPlasticity(const Plasticity& p) { configure(material_.springs.plasticity, p); }
void DynamicSurface::setStiffnessLaw(const ResponseLaw& law) { configure(material_.springs.law, law); }
void DynamicSurface::setDampingLaw(const ResponseLaw& law) { configure(material_.dampingLaw, law); }

void DynamicSurface::setMaxPointForce(double f) { forces_.maxPointForce = requirePositive(f, "max_point_force"); }
void DynamicSurface::setConstraintStiffnessFactor(double f) {
    forces_.constraintStiffnessFactor = requirePositive(f, "constraint_stiffness_factor");
}

double DynamicSurface::meshCurvature(int index, int direction) const {
    requireInRange(index, "index", 0, g() * h() - 1);
    const int i = index / h(), j = index % h();
    if (i < 1 || j < 1 || i > g() - 2 || j > h() - 2) throw std::invalid_argument("index: must be an interior point");
    if (direction != 0 && direction != 1) throw std::invalid_argument("direction: 0 (u) or 1 (v)");
    return constraints().meshCurvature(state_.d, index, direction);
}

const Points& DynamicSurface::meshVelocities() {
    state_.A.apply(state_.v, scratch_.meshVelocity);
    return scratch_.meshVelocity;
}

void DynamicSurface::setPoles(const Points& poles) {
    if (poles.rows() != state_.poles().rows()) throw std::invalid_argument("poles: wrong number of rows");
    if (!withinRange(poles)) throw std::invalid_argument("poles: must be finite and within +-1e9");
    state_.mutablePoles() = poles;
    state_.v.setZero();
    if (!mirror_.empty()) mirror_.project(state_.mutablePoles(), state_.v);
    held_.capture(state_.poles());
    held_.snap(state_.mutablePoles(), state_.v);  // (the linked poles onto their masters)
    state_.avValid = false;
    localGlobal_.restart();
    state_.sampleMesh();
    wake();
}

void DynamicSurface::continueFrom(DynamicSurface& live, bool keepMaps) {
    if (live.g() != g() || live.h() != h() || live.poles().rows() != poles().rows())
        throw std::invalid_argument("edit: the edited surface has another sampling or control net than the live one");
    setPoles(live.poles());
    setVelocities(live.velocities());
    material_.springs.setRest(live.material_.springs.rest());
    material_.bending.setReference(live.material_.bending.reference());
    if (keepMaps) {
        Material &mine = material_, &theirs = live.material_;
        for (auto [to, from] : {std::pair{&mine.massMap, &theirs.massMap}, {&mine.dampingMap, &theirs.dampingMap},
                                {&mine.stiffnessMap, &theirs.stiffnessMap}, {&mine.bendingMap, &theirs.bendingMap},
                                {&pullMap(), &live.pullMap()}})
            if (to->rows() != from->rows() || to->cols() != from->cols() || to->values() != from->values())
                to->setValues(from->rows(), from->cols(), from->values());
    }
    if (std::string(tool().name()) == live.tool().name()) {
        live.tool().copySettings(tool());
        forces_.swapTool(live.forces_);
    }
    forces_.pull().takeAnchors(live.forces_.pull());
    forces_.cursor = live.forces_.cursor;
    localGlobal_.continueFrom(live.localGlobal_);  // (so the step after an edit stays second order)
    time_ = live.time_;
    work_ = live.work_;
    steps_ = live.steps_;
    touch();
}

void DynamicSurface::setPullTarget(std::shared_ptr<const PointTree> tree, double reach) {
    forces_.pull().setTarget(std::move(tree), reach);
    wake();
}

void DynamicSurface::setPull(bool enabled, double strength) {
    DataSprings& pull = forces_.pull();
    pull.setStrength(strength);
    pull.setEnabled(enabled);
    wake();
}

void DynamicSurface::holdPoles(const std::vector<int>& indices, const std::vector<PoleLink>& links) {
    std::vector<int> sorted = indices;
    std::sort(sorted.begin(), sorted.end());
    mirror_.requireSymmetric(sorted);
    held_.set(indices, links, state_.mutablePoles());
    held_.expand(state_.v);
    state_.sampleMesh();
    state_.avValid = false;
    localGlobal_.restart();
    wake();
}

void DynamicSurface::setSymmetry(int direction, const Vec3& point, const Vec3& normal) {
    if (direction == -1) {
        mirror_.clear();
    } else {
        mirror_.set(direction, point, normal, state_.surface, g(), h(), held_.indices());
        mirror_.project(state_.mutablePoles(), state_.v);
        held_.capture(state_.poles());
        state_.sampleMesh();
    }
    clearForces();
    state_.avValid = false;
    localGlobal_.restart();
    wake();
}

bool DynamicSurface::snapToConstraints() {
    const bool mirrored = !mirror_.empty() && mirror_.project(state_.mutablePoles(), state_.v);
    return (!held_.empty() && held_.snap(state_.mutablePoles(), state_.v)) || mirrored;
}

void DynamicSurface::setWalls(const std::vector<PoleWall>& walls) {
    walls_.set(walls, state_.poles().rows());
    if (walls_.project(state_.mutablePoles(), state_.v, [this](int p) { return held_.constrained(p); })) {
        snapToConstraints();
        state_.sampleMesh();
    }
    state_.avValid = false;
    localGlobal_.restart();
    wake();
}

void DynamicSurface::setVelocities(const Points& v) {
    if (v.rows() != state_.v.rows()) throw std::invalid_argument("velocities: wrong number of rows");
    if (!v.allFinite()) throw std::invalid_argument("velocities: contain NaN or Inf");
    state_.v = v;
    held_.expand(state_.v);
    state_.avValid = false;
    localGlobal_.restart();
    wake();
}

int DynamicSurface::meshIndexAt(double u, double v) const {
    if (!std::isfinite(u) || !std::isfinite(v)) throw std::invalid_argument("uv: must be finite");
    const auto& us = state_.A.us();
    const auto& vs = state_.A.vs();
    const double fu = (u - us.front()) / (us.back() - us.front()), fv = (v - vs.front()) / (vs.back() - vs.front());
    if (fu < -1e-12 || fu > 1 + 1e-12 || fv < -1e-12 || fv > 1 + 1e-12)
        throw std::invalid_argument("uv: outside the parametric domain");
    const int a = static_cast<int>(std::lround(std::clamp(fu, 0.0, 1.0) * (g() - 1)));
    const int b = static_cast<int>(std::lround(std::clamp(fv, 0.0, 1.0) * (h() - 1)));
    return a * h() + b;
}

std::pair<double, double> DynamicSurface::meshParameters(int index) const {
    if (index < 0 || index >= g() * h()) throw std::invalid_argument("index: mesh index out of range");
    return {state_.A.u(index / h()), state_.A.v(index % h())};
}

void DynamicSurface::refreshMaterials() {
    if (!material_.refresh(state_.A)) return;
    constraints().setBendingRatio(material_.bendingRatios());  // curvature constraints beat the plate they bend
    explicit_.invalidate();
    verlet_.invalidate();
}

void DynamicSurface::setPointForce(int index, const Vec3& force) {
    forces_.setPointForce(index, force, mirror_);
    localGlobal_.restart();  // the force jumps: BDF2 restarts (see Bdf2History)
    touch();
}

void DynamicSurface::clearForces() {
    forces_.clearExternal();
    localGlobal_.restart();
    touch();
}

void DynamicSurface::setTool(const std::string& name) {
    forces_.setTool(name);
    touch();
}

void DynamicSurface::setCursor(const Cursor& c) {
    if (!c.position.allFinite() || !c.orientation.coeffs().allFinite())
        throw std::invalid_argument("cursor: position and orientation must be finite");
    if (!(c.orientation.norm() > 0)) throw std::invalid_argument("cursor: orientation must be a non-zero quaternion");
    Cursor n = c;
    n.orientation.normalize();
    Tool& t = tool();
    if (n.grab && !t.grabbed()) {
        t.grab(meshView(), n);
        localGlobal_.restart();
        touch();
    } else if (!n.grab && t.grabbed()) {
        t.release();
        // Clay keeps what it is given: the stroke's shape becomes the rest shape, its springs' rest
        // lengths and what bending measures from. Left to plastic flow alone, the strain below the
        // yield sprang back for a minute after the release (a flatten stroke undone in 30 s, a
        // free sheet curling by itself). (follow, not setReference: the state is the core's own,
        // finite by its guards, and may lie past the +-1e9 a caller's reference is held to after
        // extreme forces)
        if (material_.springs.plasticity.enabled) {
            material_.springs.resetRest(state_.d);
            material_.bending.follow(state_.d, 1.0);
            guard_.lower(kineticEnergy() + potentialEnergy());  // (the potential energy just dropped)
        }
        localGlobal_.restart();
        touch();
    }
    forces_.cursor = n;
}

StepReport DynamicSurface::step(double dt) {
    if (!(dt >= kMinDt) || !std::isfinite(dt)) throw std::invalid_argument("dt: must be finite and >= 1e-9 s");
    refreshMaterials();
    const std::uint64_t key[6] = {material_.massMap.version(), material_.dampingMap.version(),
                                  material_.stiffnessMap.version(), constraints().version(), material_.bendingMap.version(),
                                  pullMap().version()};
    for (int i = 0; i < 6; ++i)
        if (key[i] != wakeKey_[i]) { wake(); wakeKey_[i] = key[i]; }
    // A held tool keeps the surface awake; its forces are refreshed by the integrator each step.
    const bool grabbed = tool().grabbed();
    if (grabbed) sleep_.wake();
    StepReport r;
    if (sleep_.asleep()) {
        r.slept = true;
        return r;
    }
    // The pull is taken where the step starts, as the point forces are held over it.
    if (forces_.pull().active() && !state_.avValid) {  // (its damper reads the mesh's velocity)
        state_.A.apply(state_.v, state_.av);
        state_.avValid = true;
    }
    forces_.applyPull(state_.d, state_.av, state_.spacingU, state_.spacingV, material_.masses(), dt);
    StepModel m = model();
    const bool localGlobal = solver_.kind == IntegratorKind::LocalGlobal;
    const bool verlet = localGlobal && verlet_.stable(m, dt);
    const bool guard = guardsEnergy(dt, verlet);
    chooseRegion(localGlobal && !verlet && !guard && regionalScene());
    const ActiveRegion& region = region_.region();
    const GridRect& P = region.poles;
    verlet_.clearStepPotential();
    if (!guard) guard_.reset();
    else guard_.begin([this] { return kineticEnergy() + potentialEnergy(); });
    // Where the step starts: for a refused step, the work of the applied forces and local/global's A v.
    P.forSpans([&](const auto& q) {
        q(state_.polesAtStart) = q(state_.poles());
        q(state_.velocitiesAtStart) = q(state_.v);
    });
    const bool tracksWork = forces_.hasExternal() || grabbed;
    if (tracksWork || localGlobal) region.halo.forSpans([&](const auto& q) { q(state_.meshAtStart) = q(state_.d); });
    if (!localGlobal) {
        state_.avValid = false;
        localGlobal_.restart();
    }
    if (!verlet) verlet_.invalidate();
    switch (solver_.kind) {
        case IntegratorKind::Explicit: r = explicit_.step(m, dt); break;
        case IntegratorKind::ImplicitCG: r = cg_.step(m, dt); break;
        case IntegratorKind::LocalGlobal:
            if (verlet) {
                r = verlet_.step(m, dt);
                localGlobal_.restart();
            } else {
                r = localGlobal_.step(m, dt);
            }
            break;
    }
    if (solver_.kind != IntegratorKind::Explicit) explicit_.invalidate();  // the state moved under its acceleration
    bool finite = true;
    P.forSpans([&](const auto& q) { finite = finite && q(state_.poles()).allFinite() && q(state_.v).allFinite(); });
    if (!finite) {
        restoreStepStart(true);
        r.refused = true;
        r.reason = "the step would produce NaN or Inf; state kept (reduce dt or stiffness)";
        return r;
    }
    // Walls, then symmetry (symmetric walls keep a symmetric net behind them), then the held set
    // (symmetric, so snapping the held poles back keeps the symmetry).
    const bool walled = !walls_.empty() &&
                        walls_.project(state_.mutablePoles(), state_.v, [this](int p) { return held_.constrained(p); });
    if (snapToConstraints() || walled) {
        sampleRegion();
        state_.avValid = false;
    }
    if (walled) {
        localGlobal_.restart();        // (BDF2's history would carry the pole back out)
        verlet_.clearStepPotential();  // (Verlet's potential and forces were the net's before the
        verlet_.invalidate();          // wall moved it)
    }
    // The work of the applied forces over the step (forces held over the step).
    const double work = tracksWork ? forces_.appliedWork(state_.d, state_.meshAtStart, region.halo) : 0.0;
    if (guard && !limitEnergy(work, r)) return r;
    work_ += work;
    SpringMesh& springs = material_.springs;
    if (springs.plasticity.enabled) {
        springs.applyPlasticity(state_.d, dt, region.whole ? nullptr : &region.halo);
        // Between strokes the reference follows plastic flow (under a stroke it holds, so the
        // stroke's shape is fair; the release commits it).
        if (!grabbed)
            material_.bending.follow(state_.d, std::min(1.0, springs.plasticity.rate * dt), region.whole ? nullptr : &region.mesh);
        verlet_.invalidate();  // the rest lengths moved under the forces Verlet carries over
    }
    time_ += dt;
    ++steps_;
    checkSleep();
    return r;
}

bool DynamicSurface::regionalScene() const {
    return mirror_.empty() && held_.links().empty() && constraints().empty() && !forces_.hasExternal() &&
           material_.springs.law.kind == LawKind::Linear && material_.dampingLaw.kind == LawKind::Linear;
}

void DynamicSurface::chooseRegion(bool allowed) {
    GridRect reach;
    const bool known = tool().reach(g(), h(), reach);
    const double floorSpeed = sleep_.settings.tolerance * state_.size;
    const Points* force = nullptr;
    double floorForce = 0;
    if (allowed && solver_.region.enabled && region_.wantsForces()) {
        // After an edit: where the net is out of balance (the sleep test's force and measure).
        forces_.potential(material_, state_.d);
        state_.A.applyTransposed(forces_.total(), scratch_.poleForce);
        held_.reduce(scratch_.poleForce);
        force = &scratch_.poleForce;
        floorForce = sleep_.settings.tolerance * material_.stiffnessMap.mean() * state_.size;
    }
    if (!region_.choose(state_.A, solver_.region, allowed, known, reach, state_.v, floorSpeed, force, floorForce)) return;
    const ActiveRegion& region = region_.region();
    if (region.whole) return;
    // What falls outside stops where it is (it moved slower than the region chases), and
    // local/global starts its history afresh from there.
    for (Eigen::Index k = 0; k < state_.v.rows(); ++k)
        if (!region.poles.containsIndex(k)) state_.v.row(k).setZero();
    state_.avValid = false;
    localGlobal_.restart();
}

void DynamicSurface::sampleRegion() {
    const ActiveRegion& region = region_.region();
    if (region.whole) state_.sampleMesh();
    else state_.A.applyTo(state_.poles(), state_.d, region.mesh);
}

void DynamicSurface::prepare(double dt) {
    if (!(dt >= kMinDt) || !std::isfinite(dt)) throw std::invalid_argument("dt: must be finite and >= 1e-9 s");
    refreshMaterials();
    StepModel m = model();
    m.ensureMass();
    if (solver_.kind != IntegratorKind::LocalGlobal) return;
    verlet_.stable(m, dt);
    m.ensureSystem(LocalGlobalIntegrator::systemStep(solver_, dt), true);
}

double DynamicSurface::verletStepLimit() {
    refreshMaterials();
    StepModel m = model();
    return verlet_.stepLimit(m);
}

bool DynamicSurface::guardsEnergy(double dt, bool verlet) const {
    if (!guard_.settings.enabled) return false;
    // Verlet is stable here but not a descent method: the guard stays as for every explicit scheme.
    if (verlet) return true;
    // The symmetry's projection is not energy-neutral where something is not symmetric (a penalty
    // constraint on one side, a painted map): the guard takes out what it would put in.
    if (!mirror_.empty()) return true;
    // Walls put a pole back against the springs that carried it out: the guard takes out what
    // they would put in (as it is for a real wall, whose reaction does no work).
    if (!walls_.empty()) return true;
    // Point, tangent and normal constraints project onto convex sets, so they keep the guarantee.
    if (solver_.kind != IntegratorKind::LocalGlobal || material_.springs.law.kind != LawKind::Linear ||
        constraints().anyNonConvex())
        return true;
    // Local/global's descent guarantee is exact arithmetic's: the solve's rounding grows with the
    // system's stiffness-to-mass ratio (~ dt^2 8 k_max / m_min, Gershgorin), and past 1e8 it can
    // put measurable energy into a resting mesh (seen: 4.5e4 from rest at a ratio of 1e13).
    return dt * dt * 8 * material_.maxStiffness() > 1e8 * material_.minMass();
}

bool DynamicSurface::limitEnergy(double work, StepReport& r) {
    // Below this floor energy is rounding noise: 1e-12 of a surface-sized stretch at the mean stiffness.
    const double floor = 1e-12 * material_.stiffnessMap.mean() * state_.size * state_.size;
    const double ke = kineticEnergy(), pe = verlet_.stepPotential() >= 0 ? verlet_.stepPotential() : potentialEnergy();
    const EnergyGuard::Verdict verdict = guard_.judge(ke, pe, work, floor);
    if (verdict.kind == EnergyGuard::Verdict::Accept) return true;
    r.energyLimited = true;
    if (verdict.kind == EnergyGuard::Verdict::Scale) {
        state_.v *= verdict.scale;
        state_.av *= verdict.scale;
        localGlobal_.restart();
        explicit_.invalidate();
        verlet_.invalidate();
        r.reason = "the step would have created energy; velocities scaled back to the energy ceiling (reduce dt or stiffness)";
        return true;
    }
    restoreStepStart(false);
    r.refused = true;
    r.reason = "the step would have created energy: positions kept, motion stopped (reduce dt or stiffness, or use local_global)";
    return false;
}

void DynamicSurface::checkSleep() {
    double fastest = 0;  // (nothing outside the region moves)
    region_.region().poles.forSpans([&](const auto& q) { fastest = std::max(fastest, q(state_.v).cwiseAbs().maxCoeff()); });
    if (!sleep_.watching(tool().grabbed()) || !sleep_.quietStep(fastest, state_.size)) return;
    // Net force check, once, at the moment the surface would fall asleep.
    Points &dd = scratch_.meshVelocity, &fp = scratch_.poleForce;
    dd.setZero();
    forces_.all(material_, state_.d, dd);
    state_.A.applyTransposed(forces_.total(), fp);
    held_.reduce(fp);  // (the held poles' reactions are not motion)
    if (sleep_.settle(fp.cwiseAbs().maxCoeff(), material_.stiffnessMap.mean() * state_.size)) {
        region_.forget();
        state_.v.setZero();
        state_.avValid = false;
        localGlobal_.restart();
        verlet_.invalidate();
    }
}

double DynamicSurface::kineticEnergy() {
    refreshMaterials();
    if (!state_.avValid) state_.A.apply(state_.v, scratch_.meshVelocity);  // local/global and Verlet keep A v
    const double* w = (state_.avValid ? state_.av : scratch_.meshVelocity).data();
    const Eigen::VectorXd& m = material_.masses();
    double e = 0;
    for (Eigen::Index i = 0; i < m.size(); ++i) e += m[i] * (w[3 * i] * w[3 * i] + w[3 * i + 1] * w[3 * i + 1] + w[3 * i + 2] * w[3 * i + 2]);
    return 0.5 * e;
}

void DynamicSurface::restoreStepStart(bool keepVelocity) {
    region_.region().poles.forSpans([&](const auto& q) {  // (the step moved nothing else)
        q(state_.mutablePoles()) = q(state_.polesAtStart);
        if (keepVelocity) q(state_.v) = q(state_.velocitiesAtStart);
        else q(state_.v).setZero();
    });
    state_.avValid = false;
    localGlobal_.restart();
    sampleRegion();
    explicit_.invalidate();
    verlet_.invalidate();
}

double DynamicSurface::potentialEnergy() {
    refreshMaterials();
    return forces_.potentialEnergy(material_, state_.d);
}

const Points& DynamicSurface::potentialGradient() {
    refreshMaterials();
    forces_.potential(material_, state_.d);
    Points& fp = scratch_.poleForce;
    state_.A.applyTransposed(forces_.total(), fp);
    fp = -fp;
    return fp;
}

Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> DynamicSurface::curvatureGrid() const {
    const auto& ops = state_.A.derivativeOperators(state_.surface);
    const Eigen::Index S = state_.d.rows();
    Points der[5];
    for (int k = 0; k < 5; ++k) {
        der[k].resize(S, 3);
        ops[k].multiply(state_.poles(), der[k]);
    }
    Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> out(S, 6);
    for (Eigen::Index i = 0; i < S; ++i) {
        SurfaceDerivatives sd;
        sd.s = state_.d.row(i);
        sd.su = der[0].row(i); sd.sv = der[1].row(i);
        sd.suu = der[2].row(i); sd.suv = der[3].row(i); sd.svv = der[4].row(i);
        const Curvature c = curvatureFrom(sd);
        out.row(i) << c.ku, c.kv, c.kmin, c.kmax, c.mean, c.gauss;
    }
    return out;
}

}  // namespace hs
