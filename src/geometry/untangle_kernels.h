// Per-corner energies of the untangler (src/geometry/untangle.cpp), kept in a header so the tests
// can check gradients and Hessians against finite differences.
//
// A corner tetrahedron is (p_c, p_n0, p_n1, p_n2) with edge vectors e_k = p_nk - p_c, and the
// Jacobian F = [e0 e1 e2] (in units of the reference edge length). Phase 1's energy
//     f(F) = tr(F^T F) / chi(det F, eps)^(2/3) + lambda (det^2 + 1) / chi(det F, eps)
// (Garanzha et al. 2021, eq. 3-4) depends on F only through I2 = |F|^2 and I3 = det F, so it is
// isotropic, and its 9x9 Hessian has the closed-form eigensystem of Smith, de Goes and Kim
// ("Analytic eigensystems for isotropic distortion energies", ACM TOG 2019): with the signed SVD
// F = U diag(s) V^T, the twist and flip matrices U (e_i e_j^T -+ e_j e_i^T) V^T / sqrt 2 are
// eigenvectors with eigenvalues 2 f_2 +- f_3 s_k ({i, j, k} = {0, 1, 2}), and the three scaling
// directions U diag(w) V^T span the remaining 3x3 block d^2 f / d s^2. Clamping these nine
// eigenvalues at 0 gives the projected (positive semi-definite) Hessian used by Newton's method.
#pragma once

#include "hexpeel/quad_surface.h"

#include <Eigen/Dense>

#include <cmath>
#include <limits>

namespace hexpeel::untangle_detail {

using Mat9 = Eigen::Matrix<double, 9, 9>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

/// chi(D, eps) in a form that does not cancel for D << 0 (the papers' regularized determinant).
inline double chi(double d, double eps) {
  const double r = std::sqrt(eps * eps + d * d);
  return d > 0 ? 0.5 * (d + r) : 0.5 * eps * eps / (r - d);
}
inline double chi_deriv(double d, double eps) {
  return 0.5 + 0.5 * d / std::sqrt(eps * eps + d * d);
}

/// Phase 1 kernel: the regularized Winslow + volume energy of one corner tetrahedron.
struct WinslowKernel {
  double eps, lambda;
  double operator()(const Vec3& e0, const Vec3& e1, const Vec3& e2, Vec3& g0, Vec3& g1, Vec3& g2,
                    double& det) const {
    const Vec3 d0 = e1.cross(e2), d1 = e2.cross(e0), d2 = e0.cross(e1);  // d det / d e_k
    det = e0.dot(d0);
    const double c1 = chi(det, eps), c2 = std::cbrt(c1 * c1), c3 = chi_deriv(det, eps);
    const double tr = e0.squaredNorm() + e1.squaredNorm() + e2.squaredNorm();
    const double fw = tr / c2, fv = (det * det + 1.0) / c1;
    const double kd = -(2.0 / 3.0) * fw * c3 / c1 + lambda * (2.0 * det - fv * c3) / c1;
    g0 = (2.0 / c2) * e0 + kd * d0;
    g1 = (2.0 / c2) * e1 + kd * d1;
    g2 = (2.0 / c2) * e2 + kd * d2;
    return fw + lambda * fv;
  }

  /// The 9x9 Hessian of f with respect to vec(F) = (e0, e1, e2), with every eigenvalue clamped at
  /// 0 when `project` (else exact). Returns f.
  double hessian(const Vec3& e0, const Vec3& e1, const Vec3& e2, Mat9& h, bool project) const {
    Eigen::Matrix3d f;
    f << e0, e1, e2;
    const double det = f.determinant(), i2 = f.squaredNorm();
    const double r = std::sqrt(eps * eps + det * det);
    const double c = chi(det, eps), cd = 0.5 + 0.5 * det / r, cdd = 0.5 * eps * eps / (r * r * r);
    const double cm23 = 1.0 / std::cbrt(c * c), cm53 = cm23 / c, cm83 = cm53 / c;
    const double q = det * det + 1.0;
    // f = a(I2, I3); its first and second derivatives (a_22 = 0).
    const double a2 = cm23;
    const double a3 = -(2.0 / 3.0) * i2 * cm53 * cd + lambda * (2.0 * det / c - q * cd / (c * c));
    const double a23 = -(2.0 / 3.0) * cm53 * cd;
    const double a33 = i2 * ((10.0 / 9.0) * cm83 * cd * cd - (2.0 / 3.0) * cm53 * cdd) +
                       lambda * (2.0 / c - 4.0 * det * cd / (c * c) - q * cdd / (c * c) +
                                 2.0 * q * cd * cd / (c * c * c));
    // Signed SVD: U, V rotations, the sign of det carried by s(2).
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(f, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d u = svd.matrixU(), v = svd.matrixV();
    Vec3 s = svd.singularValues();
    if (u.determinant() < 0) u.col(2) *= -1.0, s(2) *= -1.0;
    if (v.determinant() < 0) v.col(2) *= -1.0, s(2) *= -1.0;
    // Scaling block: d^2 a / ds_i ds_j with dI2/ds_i = 2 s_i, dI3/ds_i = s_j s_k.
    Eigen::Matrix3d k;
    const Vec3 pi(s(1) * s(2), s(0) * s(2), s(0) * s(1));
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const double t2i = 2.0 * s(i), t2j = 2.0 * s(j);
        k(i, j) = a23 * (t2i * pi(j) + pi(i) * t2j) + a33 * pi(i) * pi(j);
        if (i == j) k(i, j) += 2.0 * a2;
        else k(i, j) += a3 * s(3 - i - j);
      }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
    es.computeDirect(k);
    // The nine eigenpairs: eigenvector m (a 3x3 matrix, column-major into 9 entries).
    Eigen::Matrix<double, 9, 9> qm;
    Eigen::Matrix<double, 9, 1> lam;
    auto put = [&](int col, const Eigen::Matrix3d& m) {
      for (int c2 = 0; c2 < 3; ++c2)
        for (int r2 = 0; r2 < 3; ++r2) qm(3 * c2 + r2, col) = m(r2, c2);
    };
    for (int m = 0; m < 3; ++m) {
      put(m, u * es.eigenvectors().col(m).asDiagonal() * v.transpose());
      lam(m) = es.eigenvalues()(m);
    }
    constexpr double kInvSqrt2 = 0.70710678118654752440;
    const int pairs[3][3] = {{0, 1, 2}, {0, 2, 1}, {1, 2, 0}};
    for (int p = 0; p < 3; ++p) {
      const int i = pairs[p][0], j = pairs[p][1], kk = pairs[p][2];
      const Eigen::Matrix3d a = u.col(i) * v.col(j).transpose(), b = u.col(j) * v.col(i).transpose();
      put(3 + 2 * p, kInvSqrt2 * (a - b));  // twist
      lam(3 + 2 * p) = 2.0 * a2 + a3 * s(kk);
      put(4 + 2 * p, kInvSqrt2 * (a + b));  // flip
      lam(4 + 2 * p) = 2.0 * a2 - a3 * s(kk);
    }
    if (project) lam = lam.cwiseMax(0.0);
    h.noalias() = qm * lam.asDiagonal() * qm.transpose();
    return i2 * cm23 + lambda * q / c;
  }
};

/// Phase 2 kernel: exp(beta (s_ref - s)) of the corner scaled Jacobian s, +inf below the floor,
/// plus mu times the phase 1 energy (eps ~ 0). s is scale invariant, so without the second term
/// an edge can shrink to nothing (a pillow hex collapsing onto the boundary) at no cost; the
/// volume part (det^2 + 1) / det of the Winslow energy keeps every corner's size.
struct QualityKernel {
  double beta, s_ref, floor;  ///< a trial point with s <= floor is rejected (energy +inf)
  double mu;                  ///< weight of the Winslow regularizer
  WinslowKernel winslow;
  double operator()(const Vec3& e0, const Vec3& e1, const Vec3& e2, Vec3& g0, Vec3& g1, Vec3& g2,
                    double& s) const {
    const Vec3 d0 = e1.cross(e2), d1 = e2.cross(e0), d2 = e0.cross(e1);
    const double det = e0.dot(d0);
    const double a2 = e0.squaredNorm(), b2 = e1.squaredNorm(), c2 = e2.squaredNorm();
    const double l = std::sqrt(a2 * b2 * c2);
    if (!(l > 1e-300)) {
      s = -1.0;
      g0 = g1 = g2 = Vec3::Zero();
      return std::numeric_limits<double>::infinity();
    }
    s = det / l;
    if (s <= floor) {
      g0 = g1 = g2 = Vec3::Zero();
      return std::numeric_limits<double>::infinity();
    }
    const double f = std::exp(beta * (s_ref - s));
    const double k = -beta * f;  // df/ds
    Vec3 w0, w1, w2;
    double wdet;
    const double fw = winslow(e0, e1, e2, w0, w1, w2, wdet);
    g0 = k * (d0 / l - (s / a2) * e0) + mu * w0;
    g1 = k * (d1 / l - (s / b2) * e1) + mu * w1;
    g2 = k * (d2 / l - (s / c2) * e2) + mu * w2;
    return f + mu * fw;
  }
};

/// The 12x12 Hessian over the corner's points (p_c, p_n0, p_n1, p_n2) from the 9x9 one over
/// (e0, e1, e2): e_k = p_nk - p_c, so p_c's rows are minus the sum of the others.
inline void corner_hessian(const Mat9& hf, Mat12& h) {
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) h.block<3, 3>(3 + 3 * a, 3 + 3 * b) = hf.block<3, 3>(3 * a, 3 * b);
  for (int b = 0; b < 3; ++b) {
    const Eigen::Matrix3d col = -(hf.block<3, 3>(0, 3 * b) + hf.block<3, 3>(3, 3 * b) +
                                  hf.block<3, 3>(6, 3 * b));
    h.block<3, 3>(0, 3 + 3 * b) = col;
    h.block<3, 3>(3 + 3 * b, 0) = col.transpose();
  }
  h.block<3, 3>(0, 0) = -(h.block<3, 3>(0, 3) + h.block<3, 3>(0, 6) + h.block<3, 3>(0, 9));
}

}  // namespace hexpeel::untangle_detail
