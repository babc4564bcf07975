// How a force device's workspace maps into the document: where its middle sits, how far the
// cursor moves per mm of grip travel, and what a session force is in newtons. The session's units
// are the caller's (mm, kg, s in the workbench: forces in mN), a device renders newtons.
#pragma once
#include <stdexcept>

#include "common/types.hpp"

namespace hs {

struct DeviceMapping {
    Vec3 origin = Vec3::Zero();  ///< the workspace's middle in the document (mm)
    double scale = 1.0;          ///< mm of document per mm of grip travel
    double forceScale = 1e-3;    ///< N per session force unit (mm, kg, s: mN)

    void validate() const {
        if (!origin.allFinite()) throw std::invalid_argument("origin: must be finite");
        requireInRange(scale, "scale", 1e-6, 1e6);
        requireInRange(forceScale, "force_scale", 1e-12, 1e12);
    }
    /// The document point for a grip offset from the workspace's middle (mm, document axes).
    Vec3 position(const Vec3& gripMm) const { return origin + scale * gripMm; }
    /// A session force in newtons.
    Vec3 newtons(const Vec3& sessionForce) const { return forceScale * sessionForce; }
    /// A force in newtons in session units.
    double sessionForce(double n) const { return n / forceScale; }
    /// A grip stiffness (N/m) as the session sees it (session force per document mm).
    double sessionStiffness(double newtonsPerMetre) const { return newtonsPerMetre * 1e-3 / (scale * forceScale); }
};

}  // namespace hs
