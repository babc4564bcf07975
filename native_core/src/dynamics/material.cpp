#include "dynamics/material.hpp"

namespace hs {

Material::Material(int g, int h, double su, double sv, const Points& d)
    : massMap(1.0, "mass"), dampingMap(1.0, "damping"), stiffnessMap(100.0, "stiffness"), bendingMap(1.0, "bending"),
      springs(g, h, d), bending(g, h, su, sv, d) {
    const Eigen::Index S = static_cast<Eigen::Index>(g) * h;
    m_.setZero(S);
    gamma_.setZero(S);
    bendingRatio_.setZero(S);
    dampingMap.allowZero(true);
    bendingMap.allowZero(true);
    bendingMap.setUniform(kDefaultBending);
}

void Material::rescale(int g, int h, double su, double sv) {
    bending = BendingEnergy(g, h, su, sv, bending.reference());
    key_[3] = ~0ull;  // the operator's scaling changed: its weights again
}

bool Material::refresh(const SamplingOperator& A) {
    const std::uint64_t key[4] = {massMap.version(), dampingMap.version(), stiffnessMap.version(), bendingMap.version()};
    if (key[0] == key_[0] && key[1] == key_[1] && key[2] == key_[2] && key[3] == key_[3]) return false;
    // Densities per unit parameter area, lumped with trapezoid weights that sum to one.
    const int G = A.g(), H = A.h();
    for (int a = 0; a < G; ++a)
        for (int b = 0; b < H; ++b) {
            const double w = ((a == 0 || a == G - 1) ? 0.5 : 1.0) / (G - 1) * ((b == 0 || b == H - 1) ? 0.5 : 1.0) / (H - 1);
            const double u = static_cast<double>(a) / (G - 1), v = static_cast<double>(b) / (H - 1);
            m_[a * H + b] = massMap.at(u, v) * w;
            gamma_[a * H + b] = dampingMap.at(u, v) * w;
            bendingRatio_[a * H + b] = bendingMap.at(u, v);
        }
    springs.setStiffness(stiffnessMap, A.us(), A.vs());
    if (key[2] != key_[2] || key[3] != key_[3]) bending.setWeights(bendingMap, stiffnessMap);
    minMass_ = m_.minCoeff();
    maxDampingRate_ = (gamma_.array() / m_.array()).maxCoeff();
    // The stiffest spring, with bending as the spring stiffness of the same Laplacian row sum (16 k).
    maxStiffness_ = stiffnessMap.values().maxCoeff() + bending.maxRowSum() / 16;
    for (int i = 0; i < 4; ++i) key_[i] = key[i];
    return true;
}

}  // namespace hs
