// The smooth tool, a fairing brush: mass points within `radius` of the cursor are pulled along
// U^3 x (U the umbrella operator), the gradient flow of the discrete curvature variation,
// weighted by the falloff.
#include <memory>

#include "tools_and_constraints/tool.hpp"

namespace hs::tools::smooth {
namespace {

enum { Radius, Strength };
constexpr ToolInfo kInfo{"smooth", "Smooth", "Smooth: a fairing brush toward lower curvature variation under the cursor",
                         3, true,
                         {{{"radius", 10.0, false, "brush radius", "radius (mm)", true},
                           {"strength", 1.0, false, "fairing force per unit of U^3 x", "strength"}}}};

// Umbrella operator: mean of the 4-neighbours minus the point.
void umbrella(const Points& x, int g, int h, Points& out) {
    for (int i = 0; i < g; ++i)
        for (int j = 0; j < h; ++j) {
            Vec3 s = Vec3::Zero();
            int n = 0;
            if (i > 0) { s += x.row((i - 1) * h + j).transpose(); ++n; }
            if (i + 1 < g) { s += x.row((i + 1) * h + j).transpose(); ++n; }
            if (j > 0) { s += x.row(i * h + j - 1).transpose(); ++n; }
            if (j + 1 < h) { s += x.row(i * h + j + 1).transpose(); ++n; }
            out.row(i * h + j) = (s / n).transpose() - x.row(i * h + j);
        }
}

class SmoothTool final : public Tool {
public:
    SmoothTool() : Tool(kInfo) {}
    void grab(const MeshView& mesh, const Cursor&) override {
        u1_.resize(mesh.d.rows(), 3);
        u2_.resize(mesh.d.rows(), 3);
        u3_.resize(mesh.d.rows(), 3);
        time_ = 0;
        grabbed_ = true;
    }

protected:
    void computeForces(const MeshView& mesh, const Cursor& cursor) override {
        umbrella(mesh.d, mesh.g, mesh.h, u1_);
        umbrella(u1_, mesh.g, mesh.h, u2_);
        umbrella(u2_, mesh.g, mesh.h, u3_);
        for (Eigen::Index i = 0; i < mesh.d.rows(); ++i) {
            const double w = falloffWeight(falloff(), (mesh.d.row(i).transpose() - cursor.position).norm() / p(Radius));
            if (w > 0) emit(static_cast<int>(i), p(Strength) * w * u3_.row(i).transpose());
        }
    }

private:
    Points u1_, u2_, u3_;
};

}  // namespace

std::unique_ptr<Tool> make() { return std::make_unique<SmoothTool>(); }

}  // namespace hs::tools::smooth
