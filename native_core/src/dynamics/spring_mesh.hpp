// The mass-spring network over the g x h mesh: structural springs to the four nearest
// neighbours and springs along both diagonals, rest lengths from the initial shape.
#pragma once
#include <Eigen/Sparse>
#include <vector>

#include "common/grid_rect.hpp"
#include "geometry/bspline_surface.hpp"
#include "dynamics/material_map.hpp"
#include "dynamics/response_law.hpp"

namespace hs {

/// Plastic flow: past `yieldStrain` the rest length creeps toward the current length at `rate` (1/s).
struct Plasticity {
    bool enabled = false;
    double yieldStrain = 0.05;  ///< strain past which the rest length creeps
    double rate = 1.0;          ///< creep rate, 1/s
    /// Throws std::invalid_argument naming the first bad field.
    void validate() const {
        requirePositive(yieldStrain, "yield_strain", true);
        requirePositive(rate, "rate", true);
    }
};

class SpringMesh {
public:
    SpringMesh() = default;
    /// Builds the springs of a g x h mesh with rest lengths from `d`.
    SpringMesh(int g, int h, const Points& d);

    int size() const { return static_cast<int>(a_.size()); }
    int g() const { return g_; }
    int h() const { return h_; }
    const std::vector<int>& first() const { return a_; }
    const std::vector<int>& second() const { return b_; }
    const std::vector<double>& rest() const { return rest_; }
    const std::vector<double>& initialRest() const { return rest0_; }
    void setRest(const std::vector<double>& rest);
    void resetRest(const Points& d);  ///< rest lengths from the shape d (the current one becomes relaxed)

    /// Stiffness: one value per spring from the map at each spring's midpoint (no per-step lookups).
    void setStiffness(const MaterialMap& map, const std::vector<double>& us, const std::vector<double>& vs);
    bool uniformStiffness() const { return k_.empty(); }
    double stiffness(int s) const { return k_.empty() ? kUniform_ : k_[s]; }

    ResponseLaw law;
    Plasticity plasticity;
    double minLength = 1e-12;  ///< below this a spring has no direction and exerts no force

    /// Adds spring forces on the mesh points to f; returns the elastic energy. Also records each
    /// spring's direction and tension for tangentStiffness().
    double addForces(const Points& d, Points& f);
    /// out += K y with K the tangent stiffness at the last addForces() state (clamped to be PSD).
    void addTangentStiffness(const Points& y, Points& out) const;
    /// Local step of the local/global solver: out += scale (J t - L d), the pull of every spring
    /// toward its projected vector t (|t| its target length along d_a - d_b). Relative to d, not
    /// J t alone: J t and L d are large and nearly cancel, and the solver solves for the increment
    /// (see integrator_local_global.cpp). maxExtraStiffness caps |g(k e) - k e| / |e|: the part of a non-linear law the prefactored
    /// matrix does not hold is explicit, and stays stable only below about m / dt^2.
    /// With `energy`, also returns the elastic energy of a linear law (0 otherwise): for a linear law
    /// J t - L d is the spring force, and this is the vectorised force pass of the Verlet step.
    /// With a `window` (a rectangle of the mesh), only the springs with both ends in it are taken
    /// and only its rows of `out` are written: exact on the window shrunk by one point.
    double addProjections(const Points& d, Points& out, double maxExtraStiffness, double scale = 1.0,
                          bool energy = false, const GridRect* window = nullptr) const;
    /// Plastic flow over a step of length dt (with a `window`, of the springs with both ends in it).
    void applyPlasticity(const Points& d, double dt, const GridRect* window = nullptr);
    /// Triplets of the weighted graph Laplacian sum_s k_s (e_a - e_b)(e_a - e_b)^T.
    void addLaplacian(std::vector<Eigen::Triplet<double>>& t) const;
    double energy(const Points& d) const;

private:
    int g_ = 0, h_ = 0;
    std::vector<int> a_, b_;
    std::vector<double> rest_, rest0_, k_;
    double kUniform_ = 1.0;
    // Per-spring state of the last force evaluation, reused by the implicit solver.
    std::vector<double> dirx_, diry_, dirz_, axial_, lateral_;
    /// Springs are stored family by family (v, u, diagonal, anti-diagonal), row by row, so each
    /// family's springs in a mesh row are a contiguous run with a constant index offset.
    struct Run {
        int first;   ///< index of the first spring of the run
        int a0;      ///< mesh index of its first point a (b = a + offset)
        int offset;
        int length;
        int rowStep, colStep;  ///< where b sits from a in the grid
    };
    /// Calls f(first spring, its point a, count) for each run clipped to the springs with both
    /// ends in `window` (all springs without one).
    template <class F>
    void forRuns(const GridRect* window, F&& f) const;
    std::vector<Run> runs_;
    // Structure-of-arrays scratch for the vectorised local step.
    mutable Eigen::VectorXd x_, y_, z_, fx_, fy_, fz_, cx_, cy_, cz_, ce_;
};

}  // namespace hs
