// The flatten tool: the mass points within `radius` of where it grabs are pressed toward a plane,
// each by a spring along the plane's normal n weighted by the falloff (cylindrical: distance to the
// normal through the grab point). The plane is the surface's tangent plane where it grabs, moved
// along n to the weighted mean height of what it presses: it pushes the high points down as much
// as it pulls the low ones up (as a sculptor's flatten brush), so a free sheet does not rise whole
// and a crown is not lifted past its top. It follows the cursor along n only: moving the cursor
// along the normal raises or lowers it, sideways it stays.
//   f_i = k w_i n n^T (q - x_i),  q = m + n n^T (c - c0)   (m the weighted mean at the grab, c0 the cursor then)
// which is linear in the cursor: the haptic loop renders it as EstimateKind::Linear with D = n n^T.
#include <memory>
#include <vector>

#include "tools_and_constraints/tool.hpp"

namespace hs::tools::flatten {
namespace {

enum { Radius, Stiffness };
enum { Selected };
constexpr ToolInfo kInfo{"flatten", "Flatten",
                         "Flatten: presses the surface within its radius flat, toward its tangent plane where "
                         "it grabs, at its mean height there",
                         4, true,
                         {{{"radius", 10.0, false, "radius of the region pressed flat", "radius (mm)", true},
                           {"stiffness", 10.0, false, "spring stiffness per point toward the plane", "stiffness"}}},
                         {{{"selected", "how many mass points the grab presses"}}}};

/// The mesh's unit normal at point `k` (central differences along the net; one-sided at its edges).
Vec3 meshNormal(const MeshView& mesh, int k) {
    const int i = k / mesh.h, j = k % mesh.h;
    auto at = [&](int a, int b) -> Vec3 { return mesh.d.row(a * mesh.h + b).transpose(); };
    const Vec3 du = at(std::min(i + 1, mesh.g - 1), j) - at(std::max(i - 1, 0), j);
    const Vec3 dv = at(i, std::min(j + 1, mesh.h - 1)) - at(i, std::max(j - 1, 0));
    const Vec3 n = du.cross(dv);
    return n.norm() > 0 ? Vec3(n.normalized()) : Vec3::UnitZ();
}

class FlattenTool final : public Tool {
public:
    FlattenTool() : Tool(kInfo) {}
    void grab(const MeshView& mesh, const Cursor& cursor) override {
        const int k = nearestPoint(mesh.d, cursor.position);
        const Vec3 x = mesh.d.row(k).transpose();
        c0_ = cursor.position;
        normal_ = meshNormal(mesh, k);
        selectWithin(mesh, x, normal_, p(Radius), falloff(), points_, weights_);
        Vec3 sum = Vec3::Zero();
        double weight = 0;
        for (size_t i = 0; i < points_.size(); ++i) {
            sum += weights_[i] * mesh.d.row(points_[i]).transpose();
            weight += weights_[i];
        }
        x0_ = weight > 0 ? Vec3(sum / weight) : x;
        time_ = 0;
        grabbed_ = !points_.empty();
    }
    double slope() const override { return p(Stiffness); }  // stiffness x weight <= stiffness per point
    double readout(int i) const override { return i == Selected ? double(points_.size()) : 0.0; }

    bool reach(int, int h, GridRect& mesh) const override {
        mesh = grabbed_ ? boundingRect(points_, h) : GridRect{0, 0, 0, 0, h};
        return true;
    }

protected:
    void computeForces(const MeshView& mesh, const Cursor& cursor) override {
        const Vec3 q = x0_ + normal_.dot(cursor.position - c0_) * normal_;
        for (size_t k = 0; k < points_.size(); ++k) {
            const double height = normal_.dot(q - mesh.d.row(points_[k]).transpose());
            emit(points_[k], p(Stiffness) * weights_[k] * height * normal_);
        }
    }
    bool describeLaw(const MeshView& mesh, HapticEstimate& e) const override {
        e.kind = EstimateKind::Linear;
        e.direction = normal_ * normal_.transpose();
        e.stiffness = p(Stiffness);
        e.weightSum = 0;
        e.offsetSum.setZero();
        for (size_t k = 0; k < points_.size(); ++k) {
            e.weightSum += weights_[k];
            e.offsetSum += weights_[k] * (x0_ - c0_ - mesh.d.row(points_[k]).transpose());
        }
        e.slope = p(Stiffness) * e.weightSum;
        return true;
    }

private:
    Vec3 x0_ = Vec3::Zero();  ///< a point of the plane at the grab: the weighted mean of the selection
    Vec3 c0_ = Vec3::Zero(), normal_ = Vec3::UnitZ();
    std::vector<int> points_;
    std::vector<double> weights_;
};

}  // namespace

std::unique_ptr<Tool> make() { return std::make_unique<FlattenTool>(); }

}  // namespace hs::tools::flatten
