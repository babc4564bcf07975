// The thin-plate (bending) energy of D-NURBS (Terzopoulos & Qin) beside the springs, on the mesh's
// displacement from a reference shape r:
//   E_b = 1/2 sum_i beta_i (c_uu^2 |D_uu d|^2 + 2 |D_uv d|^2 + c_vv^2 |D_vv d|^2)  (d - r in place of d)
// with D the second differences at mesh point i and c_uu = h_v / h_u, c_vv = h_u / h_v (the mean
// spacings): the integral beta/2 (|x_uu|^2 + 2 |x_uv|^2 + |x_vv|^2) dA discretised with beta per mesh
// cell, beta_i = bending_i x stiffness_i: the bending map is a ratio to the springs' stiffness (a
// plate's rigidity over its stretch stiffness, which goes as its thickness squared), so a stiffer
// or softer material keeps its fairness. It is one constant matrix K_b = B^T W B (docs/solver.md),
// so every integrator takes it as a linear term: in the system matrix, in the Verlet bound, in CG's
// stiffness, and as the force -K_b (d - r). Nothing allocates after construction: a painted map
// only refills K_b's values in its fixed pattern.
#pragma once
#include <Eigen/Sparse>
#include <vector>

#include "common/grid_rect.hpp"
#include "geometry/bspline_surface.hpp"
#include "dynamics/material_map.hpp"

namespace hs {

class BendingEnergy {
public:
    BendingEnergy() = default;
    /// A g x h mesh with mean spacings su, sv; the reference is `reference` (S x 3).
    BendingEnergy(int g, int h, double su, double sv, const Points& reference);

    /// The second-difference operator B (rows: uu, uv, vv at each interior point, scaled as above,
    /// unweighted) and, per row, the mesh point whose weight it takes.
    static Eigen::SparseMatrix<double, Eigen::RowMajor> differences(int g, int h, double su, double sv,
                                                                    std::vector<int>* centres = nullptr);
    /// Weights bending x stiffness at each row's mesh point; refills K_b's values (no allocation).
    void setWeights(const MaterialMap& bending, const MaterialMap& stiffness);
    bool active() const { return maxRowSum_ > 0; }
    /// Each row's weight beta (for rescaling Verlet's bound when a map is painted).
    const Eigen::VectorXd& weights() const { return w_; }
    /// max_i sum_j |K_b,ij|: bounds K_b's largest eigenvalue (Gershgorin).
    double maxRowSum() const { return maxRowSum_; }
    const Eigen::SparseMatrix<double, Eigen::RowMajor>& matrix() const { return K_; }

    const Points& reference() const { return ref_; }
    /// Replaces the reference shape; throws std::invalid_argument naming "reference".
    void setReference(const Points& reference);
    /// Plastic flow: the reference moves a `fraction` of the way to the shape d (with a `window`,
    /// on its points only).
    void follow(const Points& d, double fraction, const GridRect* window = nullptr);

    /// f -= scale K_b (d - r); returns E_b. No allocation. With a `window` (a rectangle of the
    /// mesh), only its rows of f, reading d two points around it, and returns 0.
    double addForces(const Points& d, Points& f, double scale = 1.0, const GridRect* window = nullptr) const;
    /// E_b at d.
    double energy(const Points& d) const;
    /// out += K_b y (the Hessian: the energy is quadratic). No allocation.
    void addStiffness(const Points& y, Points& out) const;
    /// K_b's triplets (for the system matrix and the Verlet bound).
    void addMatrix(std::vector<Eigen::Triplet<double>>& t) const;

private:
    int g_ = 0, h_ = 0;
    std::vector<int> centres_;  // each row's mesh point
    Eigen::VectorXd w_;         // each row's weight
    /// K_b's value k gets sum of weight(row) * coefficient over its contributions (B^T W B).
    struct Contribution {
        int value, row;
        double coefficient;
    };
    std::vector<Contribution> contributions_;
    Eigen::SparseMatrix<double, Eigen::RowMajor> K_;
    double maxRowSum_ = 0;
    Points ref_;
    mutable Points diff_, prod_;
};

}  // namespace hs
