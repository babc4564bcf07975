// The curvature variation of a mesh (what Fair relaxes and a fit bridges holes with): its third
// differences x_uuu, x_uuv, x_uvv, x_vvv, whose null space is the quadratic shapes.
#pragma once
#include <Eigen/Sparse>
#include <vector>

namespace hs {

/// C (rows: the third differences at each point of a g x h mesh where they fit, scaled to a
/// square cell by r = sqrt(h_v / h_u), the mixed ones by sqrt(3) so |C x|^2 is |grad^3 x|^2) and
/// each row's mesh point in `centre`.
Eigen::SparseMatrix<double> curvatureVariation(int g, int h, double su, double sv, std::vector<int>& centre);

}  // namespace hs
