// The rope: tied to the nearest mass point; pulls, never pushes; stiff past `threshold`; its rest
// length reels in from the grab distance to zero over `reel_time`.
#include <algorithm>
#include <cmath>
#include <memory>

#include "dynamics/material_map.hpp"
#include "tools_and_constraints/tool.hpp"

namespace hs::tools::rope {
namespace {

enum { Stiffness, StiffStiffness, Threshold, ReelTime };
enum { RestLength, Gain };
constexpr ToolInfo kInfo{"rope", "Rope", "Rope: grabs the nearest mass point; pulls, cannot push; reels in over 1 s",
                         0, false,
                         {{{"stiffness", 10.0, false, "force per length below the threshold", "stiffness"},
                           {"stiff_stiffness", 200.0, false, "force per length past the threshold", "taut stiffness"},
                           {"threshold", 5.0, true, "extension beyond rest length where the rope turns stiff", "slack (mm)", true},
                           {"reel_time", 1.0, true, "seconds for the rest length to reel in to zero", "reel time (s)"}}},
                         {{{"rest_length", "the rope's rest length now"},
                           {"gain", "its pull over its settings where it is tied: 1 + ROPE_PLATE_GAIN x the bending ratio there"}}}};

class RopeTool final : public Tool {
public:
    RopeTool() : Tool(kInfo) {}
    void grab(const MeshView& mesh, const Cursor& cursor) override {
        point_ = nearestPoint(mesh.d, cursor.position);
        length0_ = (mesh.d.row(point_).transpose() - cursor.position).norm();
        const double u = mesh.g > 1 ? double(point_ / mesh.h) / (mesh.g - 1) : 0.0;
        const double v = mesh.h > 1 ? double(point_ % mesh.h) / (mesh.h - 1) : 0.0;
        gain_ = 1.0 + (mesh.bending ? kRopePlateGain * mesh.bending->at(u, v) : 0.0);
        time_ = 0;
        grabbed_ = true;
    }
    int anchor() const override { return grabbed_ ? point_ : -1; }
    bool reach(int, int h, GridRect& mesh) const override {
        mesh = grabbed_ ? GridRect{point_ / h, point_ / h + 1, point_ % h, point_ % h + 1, h} : GridRect{0, 0, 0, 0, h};
        return true;
    }
    double slope() const override { return gain_ * std::max(p(Stiffness), p(StiffStiffness)); }
    double anchorSlope() const override { return appliedScale_ * slopeNow_; }
    bool implicitOnAnchor() const override { return true; }
    double readout(int i) const override { return i == RestLength ? restLengthAt(time_) : i == Gain ? gain_ : 0.0; }

protected:
    void computeForces(const MeshView& mesh, const Cursor& cursor) override {
        const Vec3 x = mesh.d.row(point_).transpose();
        const Vec3 toCursor = cursor.position - x;
        const double dist = toCursor.norm();
        const double ext = dist - restLengthAt(forceTime_);
        slopeNow_ = 0;
        if (ext <= 0 || !(dist > 0)) return;  // a slack rope transmits nothing: it cannot push
        const double k = p(Stiffness), kStiff = p(StiffStiffness), threshold = p(Threshold);
        slopeNow_ = gain_ * (ext < threshold ? k : kStiff);
        const double tension = gain_ * (k * std::min(ext, threshold) + kStiff * std::max(0.0, ext - threshold));
        emit(point_, tension / dist * toCursor);
    }
    bool describeLaw(const MeshView& mesh, HapticEstimate& e) const override {
        e.kind = EstimateKind::Rope;
        e.points = 1;
        e.x[0] = mesh.d.row(point_).transpose();
        e.stiffness = gain_ * p(Stiffness);
        e.stiffStiffness = gain_ * p(StiffStiffness);
        e.threshold = p(Threshold);
        e.length0 = length0_;
        e.reelTime = p(ReelTime);
        e.slope = slope();
        return true;
    }

private:
    double restLengthAt(double t) const {
        const double reel = p(ReelTime);
        return reel > 0 ? length0_ * std::max(0.0, 1.0 - t / reel) : 0.0;
    }
    double slopeNow_ = 0;  ///< d tension / d extension at the last forces (0 slack)
    int point_ = -1;
    double length0_ = 0;
};

}  // namespace

std::unique_ptr<Tool> make() { return std::make_unique<RopeTool>(); }

}  // namespace hs::tools::rope
