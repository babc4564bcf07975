#include "dynamics/mirror_symmetry.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hs {

namespace {
bool symmetricKnots(const std::vector<double>& k) {
    const double scale = std::max(1.0, std::abs(k.front()) + std::abs(k.back()));
    const double sum = k.front() + k.back();
    for (std::size_t i = 0; i < k.size(); ++i)
        if (std::abs(k[i] + k[k.size() - 1 - i] - sum) > 1e-12 * scale) return false;
    return true;
}
}  // namespace

void MirrorSymmetry::set(int direction, const Vec3& point, const Vec3& normal, const BSplineSurface& surface, int g,
                         int h, const std::vector<int>& held) {
    if (direction != 0 && direction != 1) throw std::invalid_argument("symmetry: direction must be 0 (u) or 1 (v)");
    if (!point.allFinite() || !normal.allFinite() || !(normal.norm() > 0))
        throw std::invalid_argument("symmetry: the plane's point and normal must be finite and the normal non-zero");
    if (!symmetricKnots((direction == 0 ? surface.knotsU() : surface.knotsV()).knots()))
        throw std::invalid_argument(std::string("symmetry: the knots along ") + (direction == 0 ? "u" : "v") +
                                    " are not symmetric (the net must be refined symmetrically)");
    MirrorSymmetry next;
    next.direction_ = direction;
    next.nu_ = surface.nu();
    next.nv_ = surface.nv();
    next.g_ = g;
    next.h_ = h;
    next.point_ = point;
    next.normal_ = normal.normalized();
    const Points& p = surface.poles();
    const double size = std::max((p.colwise().maxCoeff() - p.colwise().minCoeff()).norm(), 1e-300);
    double worst = 0;
    int at = 0;
    for (int i = 0; i < static_cast<int>(p.rows()); ++i) {
        const int j = next.mirrorPole(i);
        if (surface.rational() && std::abs(surface.weights()[i] - surface.weights()[j]) > 1e-12 * surface.weights()[i])
            throw std::invalid_argument("symmetry: the weights are not symmetric");
        const double d = (next.reflect(p.row(i).transpose()) - p.row(j).transpose()).norm();
        if (d > worst) { worst = d; at = i; }
    }
    if (worst > 1e-6 * size) {
        char text[200];
        std::snprintf(text, sizeof text, "symmetry: the surface is not symmetric in the plane (pole %d's mirror image "
                      "is %g from its partner, %g of the size)", at, worst, worst / size);
        throw std::invalid_argument(text);
    }
    next.requireSymmetric(held);
    *this = next;
}

void MirrorSymmetry::requireSymmetric(const std::vector<int>& held) const {
    if (empty()) return;
    for (int i : held) {
        const int j = mirrorPole(i);
        if (!std::binary_search(held.begin(), held.end(), j))
            throw std::invalid_argument("indices: the held poles must be symmetric like the surface (pole " +
                                        std::to_string(i) + " is held, its mirror image " + std::to_string(j) + " is not)");
    }
}

void MirrorSymmetry::addMirrored(Points& f) const {
    const int n = static_cast<int>(f.rows());
    for (int i = 0; i < n; ++i) {
        const int j = mirror(i, g_, h_);
        if (j < i) continue;
        const Vec3 fi = f.row(i).transpose(), fj = f.row(j).transpose();
        if (fi.isZero(0.0) && fj.isZero(0.0)) continue;
        f.row(i) = (fi + reflectVector(fj)).transpose();
        if (j != i) f.row(j) = (fj + reflectVector(fi)).transpose();
    }
}

void MirrorSymmetry::pointForce(Points& f, int i, const Vec3& force) const {
    const int j = mirror(i, g_, h_);
    if (j == i) {
        f.row(i) = (force + reflectVector(force)).transpose();
    } else {
        f.row(i) = force.transpose();
        f.row(j) = reflectVector(force).transpose();
    }
}

bool MirrorSymmetry::project(Points& poles, Points& v) const {
    bool moved = false;
    const int n = static_cast<int>(poles.rows());
    for (int i = 0; i < n; ++i) {
        const int j = mirrorPole(i);
        if (j < i) continue;
        const Vec3 pi = poles.row(i).transpose(), pj = poles.row(j).transpose();
        const Vec3 vi = v.row(i).transpose(), vj = v.row(j).transpose();
        Vec3 p, w;
        if (j == i) {  // on the plane
            p = pi - (pi - point_).dot(normal_) * normal_;
            w = vi - vi.dot(normal_) * normal_;
        } else {
            p = 0.5 * (pi + reflect(pj));
            w = 0.5 * (vi + reflectVector(vj));
        }
        const Vec3 q = reflect(p);
        if (p != pi || (j != i && q != pj)) moved = true;
        poles.row(i) = p.transpose();
        v.row(i) = w.transpose();
        if (j != i) {
            poles.row(j) = q.transpose();
            v.row(j) = reflectVector(w).transpose();
        }
    }
    return moved;
}

}  // namespace hs
