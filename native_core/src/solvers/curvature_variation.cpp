#include "solvers/curvature_variation.hpp"

#include <cmath>

namespace hs {

Eigen::SparseMatrix<double> curvatureVariation(int g, int h, double su, double sv, std::vector<int>& centre) {
    const double r = std::sqrt(sv / su), s3 = std::sqrt(3.0);
    const double cube[4] = {-1, 3, -3, 1}, second[3] = {1, -2, 1}, first[2] = {-1, 1};
    std::vector<Eigen::Triplet<double>> t;
    int row = 0;
    auto at = [h](int a, int b) { return a * h + b; };
    for (int a = 0; a < g; ++a)
        for (int b = 0; b < h; ++b) {
            if (a + 3 < g) {
                for (int k = 0; k < 4; ++k) t.emplace_back(row, at(a + k, b), cube[k] * r * r * r);
                centre.push_back(at(a + 1, b));
                ++row;
            }
            if (b + 3 < h) {
                for (int k = 0; k < 4; ++k) t.emplace_back(row, at(a, b + k), cube[k] / (r * r * r));
                centre.push_back(at(a, b + 1));
                ++row;
            }
            if (a + 2 < g && b + 1 < h) {  // uuv
                for (int i = 0; i < 3; ++i)
                    for (int j = 0; j < 2; ++j) t.emplace_back(row, at(a + i, b + j), second[i] * first[j] * s3 * r);
                centre.push_back(at(a + 1, b));
                ++row;
            }
            if (a + 1 < g && b + 2 < h) {  // uvv
                for (int i = 0; i < 2; ++i)
                    for (int j = 0; j < 3; ++j) t.emplace_back(row, at(a + i, b + j), first[i] * second[j] * s3 / r);
                centre.push_back(at(a, b + 1));
                ++row;
            }
        }
    Eigen::SparseMatrix<double> C(row, g * h);
    C.setFromTriplets(t.begin(), t.end());
    return C;
}


}  // namespace hs
