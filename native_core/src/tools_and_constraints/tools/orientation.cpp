// The orientation tool: five springs, from the nearest mass point and its four neighbours to the
// cursor and the ends of its x (along u) and y (along v) axes scaled to the mesh spacing.
#include <memory>

#include "tools_and_constraints/tool.hpp"

namespace hs::tools::orientation {
namespace {

enum { Stiffness };
constexpr ToolInfo kInfo{"orientation", "Orientation",
                         "Orientation: five springs turn the surface's u and v directions toward the cursor frame", 2, false,
                         {{{"stiffness", 10.0, false, "stiffness of the five springs", "stiffness"}}}};

// The five springs: offsets in the net, the cursor axis they follow (0 none, 1 x, 2 y) and its sign.
constexpr int kDi[5] = {0, 1, -1, 0, 0}, kDj[5] = {0, 0, 0, 1, -1}, kAxis[5] = {0, 1, 1, 2, 2};
constexpr double kSign[5] = {0, 1, -1, 1, -1};

class OrientationTool final : public Tool {
public:
    OrientationTool() : Tool(kInfo) {}
    void grab(const MeshView& mesh, const Cursor& cursor) override {
        center_ = nearestPoint(mesh.d, cursor.position);
        time_ = 0;
        grabbed_ = true;
    }
    int anchor() const override { return grabbed_ ? center_ : -1; }
    bool reach(int g, int h, GridRect& mesh) const override {  // (the centre and its four neighbours)
        mesh = grabbed_ ? GridRect{center_ / h, center_ / h + 1, center_ % h, center_ % h + 1, h}.grown(1, g)
                        : GridRect{0, 0, 0, 0, h};
        return true;
    }
    double slope() const override { return p(Stiffness); }

protected:
    void computeForces(const MeshView& mesh, const Cursor& cursor) override {
        const int i = center_ / mesh.h, j = center_ % mesh.h;
        const Vec3 axes[3] = {Vec3::Zero(), cursor.orientation * Vec3::UnitX(), cursor.orientation * Vec3::UnitY()};
        for (int k = 0; k < 5; ++k) {
            const int ii = i + kDi[k], jj = j + kDj[k];
            if (ii < 0 || jj < 0 || ii >= mesh.g || jj >= mesh.h) continue;
            const double spacing = kSign[k] * (kAxis[k] == 1 ? mesh.spacingU : mesh.spacingV);
            const int idx = ii * mesh.h + jj;
            emit(idx, p(Stiffness) * (cursor.position + spacing * axes[kAxis[k]] - mesh.d.row(idx).transpose()));
        }
    }
    bool describeLaw(const MeshView& mesh, HapticEstimate& e) const override {
        e.kind = EstimateKind::Orientation;
        e.stiffness = p(Stiffness);
        const int i = center_ / mesh.h, j = center_ % mesh.h;
        e.points = 0;
        for (int k = 0; k < 5; ++k) {
            const int ii = i + kDi[k], jj = j + kDj[k];
            if (ii < 0 || jj < 0 || ii >= mesh.g || jj >= mesh.h) continue;
            e.x[e.points] = mesh.d.row(ii * mesh.h + jj).transpose();
            e.axis[e.points] = kAxis[k];
            e.spacing[e.points] = kSign[k] * (kAxis[k] == 1 ? mesh.spacingU : mesh.spacingV);
            ++e.points;
        }
        e.slope = p(Stiffness) * e.points;
        return true;
    }

private:
    int center_ = -1;
};

}  // namespace

std::unique_ptr<Tool> make() { return std::make_unique<OrientationTool>(); }

}  // namespace hs::tools::orientation
