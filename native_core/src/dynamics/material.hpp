// The surface's material: the painted maps (mass, damping, stiffness, bending) and what the
// dynamics read from them: masses and damping lumped on the mesh points, the springs' stiffnesses,
// the bending energy's weights, and the extremes that bound step lengths.
#pragma once
#include <Eigen/Core>
#include <cstdint>

#include "common/types.hpp"
#include "dynamics/bending_energy.hpp"
#include "dynamics/material_map.hpp"
#include "dynamics/response_law.hpp"
#include "dynamics/spring_mesh.hpp"
#include "geometry/sampling_operator.hpp"

namespace hs {

/// The bending map's default: off (springs alone, as before it existed). 10 (beta per mesh cell 10 x
/// the stiffness there, api.FAIR_BENDING) makes rope strokes fair (tests/test_fairness.py).
constexpr double kDefaultBending = 0.0;

class Material {
public:
    /// For the mesh `d` (its rest shape) with mean spacings su, sv.
    Material(int g, int h, double su, double sv, const Points& d);

    /// Recomputes what is derived from the maps when one changed (their versions say); returns
    /// whether it did. The springs' stiffnesses are sampled at the mesh parameters us, vs.
    bool refresh(const SamplingOperator& A);
    /// The mesh's mean spacings changed (a restored reference): the bending operator's scaling.
    void rescale(int g, int h, double su, double sv);

    /// Lumped per mesh point: mass, damping coefficient, bending ratio (the bending map there).
    const Eigen::VectorXd& masses() const { return m_; }
    const Eigen::VectorXd& damping() const { return gamma_; }
    const Eigen::VectorXd& bendingRatios() const { return bendingRatio_; }
    double minMass() const { return minMass_; }
    /// The stiffest spring, with bending as the spring stiffness of the same Laplacian row sum.
    double maxStiffness() const { return maxStiffness_; }
    /// Largest damping rate gamma / m.
    double maxDampingRate() const { return maxDampingRate_; }

    MaterialMap massMap, dampingMap, stiffnessMap, bendingMap;
    SpringMesh springs;
    BendingEnergy bending;
    ResponseLaw dampingLaw;  ///< non-linear damping: multiplier g(F)/F of a point's spring-force magnitude F

private:
    Eigen::VectorXd m_, gamma_, bendingRatio_;
    std::uint64_t key_[4] = {~0ull, ~0ull, ~0ull, ~0ull};  // the maps' versions refresh() last saw
    double minMass_ = 0, maxStiffness_ = 0, maxDampingRate_ = 0;
};

}  // namespace hs
