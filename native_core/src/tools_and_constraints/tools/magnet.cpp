// The magnet: every mass point within `radius` at grab time, each on a spring to its grab offset
// from the cursor, weighted by the falloff (cylindrical: distance to the cursor's z axis).
#include <memory>
#include <vector>

#include "tools_and_constraints/tool.hpp"

namespace hs::tools::magnet {
namespace {

enum { Radius, Stiffness };
enum { Selected };
constexpr ToolInfo kInfo{"magnet", "Magnet", "Magnet: pulls every mass point within its radius, weighted by its falloff",
                         1, true,
                         {{{"radius", 10.0, false, "selection radius", "radius (mm)", true},
                           {"stiffness", 10.0, false, "spring stiffness per point", "stiffness"}}},
                         {{{"selected", "how many mass points the grab holds"}}}};

class MagnetTool final : public Tool {
public:
    MagnetTool() : Tool(kInfo) {}
    void grab(const MeshView& mesh, const Cursor& cursor) override {
        selectWithin(mesh, cursor.position, cursor.orientation * Vec3::UnitZ(), p(Radius), falloff(), points_, weights_);
        offsets_.clear();
        for (int i : points_) offsets_.push_back(mesh.d.row(i).transpose() - cursor.position);
        time_ = 0;
        grabbed_ = !points_.empty();
    }
    bool reach(int, int h, GridRect& mesh) const override {
        mesh = grabbed_ ? boundingRect(points_, h) : GridRect{0, 0, 0, 0, h};
        return true;
    }
    double slope() const override { return p(Stiffness); }  // stiffness x falloff weight <= stiffness per point
    double readout(int i) const override { return i == Selected ? double(points_.size()) : 0.0; }

protected:
    void computeForces(const MeshView& mesh, const Cursor& cursor) override {
        for (size_t k = 0; k < points_.size(); ++k) {
            const Vec3 target = cursor.position + offsets_[k];
            emit(points_[k], p(Stiffness) * weights_[k] * (target - mesh.d.row(points_[k]).transpose()));
        }
    }
    bool describeLaw(const MeshView& mesh, HapticEstimate& e) const override {
        e.kind = EstimateKind::Linear;
        e.direction.setIdentity();
        e.stiffness = p(Stiffness);
        e.weightSum = 0;
        e.offsetSum.setZero();
        for (size_t k = 0; k < points_.size(); ++k) {
            e.weightSum += weights_[k];
            e.offsetSum += weights_[k] * (offsets_[k] - mesh.d.row(points_[k]).transpose());
        }
        e.slope = p(Stiffness) * e.weightSum;
        return true;
    }

private:
    std::vector<int> points_;
    std::vector<double> weights_;
    std::vector<Vec3> offsets_;
};

}  // namespace

std::unique_ptr<Tool> make() { return std::make_unique<MagnetTool>(); }

}  // namespace hs::tools::magnet
