// Scaled Jacobian of one hexahedron, as Verdict's hex_scaled_jacobian computes it (the metric
// vtkMeshQuality reports as HexScaledJacobian; P. Knupp, "Achieving finite element mesh quality
// via optimization of the Jacobian matrix norm and associated quantities", IJNME 48, 2000).
//
// Nine 3x3 Jacobians are evaluated: one per corner, whose columns are the three edges leaving
// the corner in the right-handed order of kHexCornerFrames, and one at the centre, whose columns
// are the principal axes (the sum of the four edge vectors parallel to each parametric
// direction). Each determinant is divided by the product of its three column lengths; the
// result is the minimum of the nine. Verdict's conventions are kept exactly:
//  - a column whose squared length is <= VERDICT_DBL_MIN (1e-30, absolute, no scaling of the
//    element) makes the whole hex degenerate, whatever the other Jacobians are;
//  - a NaN Jacobian never lowers the running minimum (which starts at VERDICT_DBL_MAX), and a
//    minimum still at VERDICT_DBL_MAX at the end is what Verdict returns for degenerate hexes.
// Verdict then clamps the result to [-VERDICT_DBL_MAX, VERDICT_DBL_MAX]; a normalised value lies
// in [-1, 1] anyway, so the only value that clamp can produce is VERDICT_DBL_MAX itself, which we
// report as kDegenerateScaledJacobian.
// Input: any 8 points in VTK_HEXAHEDRON order. Output: a value in [-1, 1] or the degenerate mark.
#include "hexpeel/quality.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace hexpeel {
namespace {

constexpr double kVerdictDblMin = 1e-30;  // VERDICT_DBL_MIN: squared length below = zero length
constexpr double kVerdictDblMax = 1e30;   // VERDICT_DBL_MAX: Verdict's "no value" / degenerate

// The normalised Jacobian of the frame (a, b, c); false when a column has zero length.
bool normalized_jacobian(const Vec3& a, const Vec3& b, const Vec3& c, double& value) {
  const double la = a.squaredNorm(), lb = b.squaredNorm(), lc = c.squaredNorm();
  if (la <= kVerdictDblMin || lb <= kVerdictDblMin || lc <= kVerdictDblMin) return false;
  value = a.dot(b.cross(c)) / std::sqrt(la * lb * lc);
  return true;
}

}  // namespace

double scaled_jacobian_term(const std::array<Vec3, 8>& p, int term) {
  double value = 0.0;
  if (term == 0) {
    // Principal axes: edges along parametric x (0->1, 3->2, 4->5, 7->6), y (0->3, 1->2, 4->7,
    // 5->6) and z (0->4, 1->5, 2->6, 3->7), summed.
    const Vec3 x1 = (p[1] + p[2] + p[5] + p[6]) - (p[0] + p[3] + p[4] + p[7]);
    const Vec3 x2 = (p[2] + p[3] + p[6] + p[7]) - (p[0] + p[1] + p[4] + p[5]);
    const Vec3 x3 = (p[4] + p[5] + p[6] + p[7]) - (p[0] + p[1] + p[2] + p[3]);
    return normalized_jacobian(x1, x2, x3, value) ? value : kDegenerateScaledJacobian;
  }
  const int c = term - 1;
  const auto& f = kHexCornerFrames[c];
  return normalized_jacobian(p[f[0]] - p[c], p[f[1]] - p[c], p[f[2]] - p[c], value)
             ? value
             : kDegenerateScaledJacobian;
}

double scaled_jacobian(const std::array<Vec3, 8>& p) {
  double lowest = kVerdictDblMax;
  for (int term = 0; term < 9; ++term) {
    const double value = scaled_jacobian_term(p, term);
    if (value == kDegenerateScaledJacobian) return kDegenerateScaledJacobian;
    if (value < lowest) lowest = value;
  }
  if (lowest >= kVerdictDblMax) return kDegenerateScaledJacobian;
  return std::max(lowest, -kVerdictDblMax);
}

}  // namespace hexpeel
