// Per-corner energies of the untangler (src/geometry/untangle.cpp), kept in a header so the tests
// can check gradients and Hessians against finite differences. The untangler evaluates them hex
// by hex (`hex()`: the nine terms of a hex side by side in SIMD lanes, see HexTerms; the same
// values as operator() up to rounding); operator() is the one-corner reference.
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

#include "hexpeel/hex_mesh.h"
#include "hexpeel/quad_surface.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <limits>

namespace hexpeel::untangle_detail {

using Mat9 = Eigen::Matrix<double, 9, 9>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

/// chi(D, eps) in a form that does not cancel for D << 0 (the papers' regularized determinant).
inline double chi(double d, double eps) {
  const double r = std::sqrt(eps * eps + d * d);
  return d > 0 ? 0.5 * (d + r) : 0.5 * eps * eps / (r - d);
}

/// x^(-1/3) for x > 0, within a few ulp of 1 / std::cbrt(x) but about 4x cheaper (glibc's cbrt
/// was a quarter of the untangler's time): an exponent-halving bit guess (about 3% off) refined
/// by four Newton steps y <- y (4 - x y^3) / 3, each squaring the relative error (3e-2, 3e-3,
/// 3e-5, 3e-9, below 1e-15). Outside the normal range (and for 0, inf, NaN) it falls back to
/// the library.
inline double inv_cbrt(double x) {
  if (!(x > 1e-300 && x < 1e300)) return 1.0 / std::cbrt(x);
  uint64_t i;
  std::memcpy(&i, &x, sizeof i);
  i = 0x553ef0ff289dd796ULL - i / 3;
  double y;
  std::memcpy(&y, &i, sizeof y);
  const double t = x * (1.0 / 3.0);
  for (int k = 0; k < 4; ++k) y = y * (4.0 / 3.0) - t * (y * y) * (y * y);
  return y;
}

/// Index of the centre term in a hex mask: bit kCentre stands for the Jacobian at the hex centre.
inline constexpr int kCentre = 8;
/// Entries per hex: the 8 corner tetrahedra and the centre.
inline constexpr int kHexTerms = 9;

/// Lanes of the structure-of-arrays layout: the 9 terms padded to an even count, so that every
/// loop over them compiles to whole SSE2 pairs.
inline constexpr int kLanes = 10;

/// The 9 terms of one hex for the batched kernels, in structure-of-arrays form (lane i = term
/// i): edge vectors e_k, the cofactors d_k = d det / d e_k and det, component by component, so
/// that the per-term arithmetic runs in SIMD lanes (the library is compiled without errno and
/// trap semantics, which lets GCC vectorize the sqrt and the selects; neither changes a value;
/// the tests that include this header are not, and get the same values unvectorized).
/// Terms 0..7 are the corner tetrahedra; term 8 (kCentre) is the Jacobian at the centre, the one
/// Verdict's scaled Jacobian adds to the 8 corners: e_k = a quarter of principal axis k (the sum
/// of the 4 hex edges in direction k), so a unit cube gives e_k = unit vectors as at its corners.
/// Without it a hex can have 8 positive corners and still be inverted as a whole (measured on
/// screw2: 144 such hexes). Every term is computed whatever the mask (the padding lane is a unit
/// cube); a kernel reads only the active terms' results. Each lane does the operations of the
/// Vec3 expressions it replaces (Eigen's cross, dot and squaredNorm written out) in their order,
/// so the lane-parallel kernels gave the same bytes as the term-by-term ones they replaced
/// (without fused multiply-adds, which the default x86-64 target lacks). WinslowKernel::hex
/// equals its operator() bit for bit; QualityKernel's operator() groups its gradient and
/// barrier differently, so the two agree up to rounding.
struct HexTerms {
  alignas(16) double e[3][3][kLanes];  ///< e[k][a][i]: component a of edge vector k of term i
  alignas(16) double d[3][3][kLanes];  ///< d[k][a][i]: component a of d det / d e_k
  alignas(16) double det[kLanes];
  void load(const Vec3 (&p)[8]) {
    for (int c = 0; c < 8; ++c) {
      const auto& fr = kHexCornerFrames[c];
      for (int k = 0; k < 3; ++k)
        for (int a = 0; a < 3; ++a) e[k][a][c] = p[fr[k]][a] - p[c][a];
    }
    for (int a = 0; a < 3; ++a) {
      e[0][a][kCentre] = 0.25 * ((((p[1][a] - p[0][a]) + (p[2][a] - p[3][a])) + (p[5][a] - p[4][a])) + (p[6][a] - p[7][a]));
      e[1][a][kCentre] = 0.25 * ((((p[3][a] - p[0][a]) + (p[2][a] - p[1][a])) + (p[7][a] - p[4][a])) + (p[6][a] - p[5][a]));
      e[2][a][kCentre] = 0.25 * ((((p[4][a] - p[0][a]) + (p[5][a] - p[1][a])) + (p[6][a] - p[2][a])) + (p[7][a] - p[3][a]));
    }
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a)
        for (int i = kHexTerms; i < kLanes; ++i) e[k][a][i] = k == a ? 1.0 : 0.0;  // padding: a unit cube
    for (int k = 0; k < 3; ++k) {
      const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;  // d_k = e_k1 x e_k2
      for (int i = 0; i < kLanes; ++i) {
        d[k][0][i] = e[k1][1][i] * e[k2][2][i] - e[k1][2][i] * e[k2][1][i];
        d[k][1][i] = e[k1][2][i] * e[k2][0][i] - e[k1][0][i] * e[k2][2][i];
        d[k][2][i] = e[k1][0][i] * e[k2][1][i] - e[k1][1][i] * e[k2][0][i];
      }
    }
    for (int i = 0; i < kLanes; ++i)
      det[i] = (e[0][0][i] * d[0][0][i] + e[0][1][i] * d[0][1][i]) + e[0][2][i] * d[0][2][i];
  }
  /// |e_k|^2 per lane into out.
  void squared_norms(int k, double (&out)[kLanes]) const {
    for (int i = 0; i < kLanes; ++i)
      out[i] = (e[k][0][i] * e[k][0][i] + e[k][1][i] * e[k][1][i]) + e[k][2][i] * e[k][2][i];
  }
  /// Adds the gradients a_k e_k + b d_k of the terms of `mask` (k = 0, 1, 2) to their points:
  /// the products lane-parallel, then the sums into g term after term in lane order.
  void scatter(unsigned mask, const double (&a0)[kLanes], const double (&a1)[kLanes],
               const double (&a2)[kLanes], const double (&b)[kLanes], Vec3 (&g)[8]) const {
    alignas(16) double gk[3][3][kLanes];
    const double(*ak[3])[kLanes] = {&a0, &a1, &a2};
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a)
        for (int i = 0; i < kLanes; ++i) gk[k][a][i] = (*ak[k])[i] * e[k][a][i] + b[i] * d[k][a][i];
    for (int i = 0; i < 8; ++i) {
      if (!(mask >> i & 1u)) continue;
      const Vec3 g0(gk[0][0][i], gk[0][1][i], gk[0][2][i]), g1(gk[1][0][i], gk[1][1][i], gk[1][2][i]),
          g2(gk[2][0][i], gk[2][1][i], gk[2][2][i]);
      const auto& fr = kHexCornerFrames[i];
      g[fr[0]] += g0;
      g[fr[1]] += g1;
      g[fr[2]] += g2;
      g[i] -= g0 + g1 + g2;
    }
    if (mask >> kCentre & 1u) {
      // d e_k / d p_j = +-1/4: + for the points on the far side in direction k.
      const int i = kCentre;
      const Vec3 q0 = 0.25 * Vec3(gk[0][0][i], gk[0][1][i], gk[0][2][i]),
                 q1 = 0.25 * Vec3(gk[1][0][i], gk[1][1][i], gk[1][2][i]),
                 q2 = 0.25 * Vec3(gk[2][0][i], gk[2][1][i], gk[2][2][i]);
      g[0] -= q0 + q1 + q2;
      g[1] += q0 - q1 - q2;
      g[2] += q0 + q1 - q2;
      g[3] += -q0 + q1 - q2;
      g[4] += -q0 - q1 + q2;
      g[5] += q0 - q1 + q2;
      g[6] += q0 + q1 + q2;
      g[7] += -q0 + q1 + q2;
    }
  }
};

/// inv_cbrt over all lanes: the bit guesses one by one, the Newton steps lane-parallel.
inline void inv_cbrt_lanes(const double (&x)[kLanes], double (&y)[kLanes]) {
  bool outside = false;
  for (int i = 0; i < kLanes; ++i) {
    uint64_t b;
    std::memcpy(&b, &x[i], sizeof b);
    b = 0x553ef0ff289dd796ULL - b / 3;
    std::memcpy(&y[i], &b, sizeof b);
    outside |= !(x[i] > 1e-300 && x[i] < 1e300);
  }
  double t[kLanes];
  for (int i = 0; i < kLanes; ++i) t[i] = x[i] * (1.0 / 3.0);
  for (int k = 0; k < 4; ++k)
    for (int i = 0; i < kLanes; ++i) y[i] = y[i] * (4.0 / 3.0) - t[i] * (y[i] * y[i]) * (y[i] * y[i]);
  if (outside)
    for (int i = 0; i < kLanes; ++i)
      if (!(x[i] > 1e-300 && x[i] < 1e300)) y[i] = 1.0 / std::cbrt(x[i]);
}

/// Phase 1 kernel: the regularized Winslow + volume energy of one corner tetrahedron.
struct WinslowKernel {
  double eps, lambda;
  /// f and its gradient with respect to e0, e1, e2; `det` receives det F. One sqrt, one or two
  /// divisions and no cbrt: with r = sqrt(eps^2 + det^2), chi'(det) = chi / r exactly, and
  /// chi^(-2/3) = (1/chi)^(2/3) = (1/chi) * inv_cbrt(1/chi).
  double operator()(const Vec3& e0, const Vec3& e1, const Vec3& e2, Vec3& g0, Vec3& g1, Vec3& g2,
                    double& det) const {
    const Vec3 d0 = e1.cross(e2), d1 = e2.cross(e0), d2 = e0.cross(e1);  // d det / d e_k
    det = e0.dot(d0);
    double inv_c, inv_r;
    reciprocals(det, inv_c, inv_r);
    const double c23 = inv_c * inv_cbrt(inv_c);  // chi^(-2/3)
    const double tr = e0.squaredNorm() + e1.squaredNorm() + e2.squaredNorm();
    double k2, kd;
    const double f = finish(tr, det, inv_c, inv_r, c23, k2, kd);
    g0 = k2 * e0 + kd * d0;
    g1 = k2 * e1 + kd * d1;
    g2 = k2 * e2 + kd * d2;
    return f;
  }

  /// 1/chi(det) and 1/r with r = sqrt(eps^2 + det^2).
  void reciprocals(double det, double& inv_c, double& inv_r) const {
    const double r = std::sqrt(eps * eps + det * det);
    if (det > 0) {  // chi = (det + r) / 2: one division gives both 1/r and 1/chi
      const double q = 1.0 / (r * (det + r));
      inv_r = (det + r) * q;
      inv_c = 2.0 * r * q;
    } else {  // chi = eps^2 / (2 (r - det)), free of cancellation
      inv_r = 1.0 / r;
      inv_c = 2.0 * (r - det) / (eps * eps);
    }
  }

  /// f from tr = |F|^2, det, 1/chi, 1/r and c23 = chi^(-2/3); its gradient is k2 e_k + kd d_k.
  double finish(double tr, double det, double inv_c, double inv_r, double c23, double& k2,
                double& kd) const {
    const double fw = tr * c23, fv = (det * det + 1.0) * inv_c;
    kd = -(2.0 / 3.0) * fw * inv_r + lambda * (2.0 * det * inv_c - fv * inv_r);
    k2 = 2.0 * c23;
    return fw + lambda * fv;
  }

  /// reciprocals() lane-parallel: both branches computed, the sign of det selects.
  void reciprocals_lanes(const double (&det)[kLanes], double (&inv_c)[kLanes], double (&inv_r)[kLanes]) const {
    const double e2 = eps * eps;
    for (int i = 0; i < kLanes; ++i) {
      const double r = std::sqrt(e2 + det[i] * det[i]);
      const double q = 1.0 / (r * (det[i] + r));
      const double ir_pos = (det[i] + r) * q, ic_pos = 2.0 * r * q;
      const double ir_neg = 1.0 / r, ic_neg = 2.0 * (r - det[i]) / e2;
      inv_r[i] = det[i] > 0 ? ir_pos : ir_neg;
      inv_c[i] = det[i] > 0 ? ic_pos : ic_neg;
    }
  }
  /// The sum of f over the terms of one hex whose bit is set in `mask` (points p, local
  /// numbering; terms in lane order), the gradient added per local point into g, the min det
  /// into vmin. The same values as operator() term by term, lane-parallel.
  double hex(const Vec3 (&p)[8], unsigned mask, Vec3 (&g)[8], double& vmin) const {
    HexTerms t;
    t.load(p);
    double inv_c[kLanes], inv_r[kLanes], c23[kLanes], tr[kLanes], n1[kLanes], n2[kLanes];
    reciprocals_lanes(t.det, inv_c, inv_r);
    inv_cbrt_lanes(inv_c, c23);
    for (int i = 0; i < kLanes; ++i) c23[i] *= inv_c[i];
    t.squared_norms(0, tr), t.squared_norms(1, n1), t.squared_norms(2, n2);
    for (int i = 0; i < kLanes; ++i) tr[i] = (tr[i] + n1[i]) + n2[i];
    double fv[kLanes], k2[kLanes], kd[kLanes];
    for (int i = 0; i < kLanes; ++i) fv[i] = finish(tr[i], t.det[i], inv_c[i], inv_r[i], c23[i], k2[i], kd[i]);
    double f = 0.0;
    for (int i = 0; i < kHexTerms; ++i) {
      if (!(mask >> i & 1u)) continue;
      f += fv[i];
      vmin = std::min(vmin, t.det[i]);
    }
    t.scatter(mask, k2, k2, k2, kd, g);
    return f;
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
  /// A second, flatter exponential: + mean_weight exp(mean_beta (s_ref - s)) per term. With a
  /// small mean_beta every corner weighs nearly alike, which keeps the typical corner up while
  /// beta's term lifts the worst (0 = off).
  double mean_beta = 0.0, mean_weight = 0.0;
  /// With mean_softmin gamma > 0 (hex() only; operator() sees one term and ignores it) the mean
  /// term is per hex instead: mean_weight (-softmin) of the hex's active terms s_i, where
  /// softmin = m - log(sum_i exp(-gamma (s_i - m))) / gamma <= m = min_i s_i, and mean_beta is
  /// unused. Its gradient lifts each hex's worst terms (weights softmax(-gamma s), summing to 1
  /// per hex), so it raises the mean of the hexes' scaled Jacobians, their worst terms, where the
  /// flat per-term exponential lifts all nine terms alike.
  double mean_softmin = 0.0;
  /// A log barrier: + barrier (-log(s - floor)) per term (0 = off; needs a finite floor). The
  /// floor alone is a wall the energy does not see coming: L-BFGS steps keep hitting it and the
  /// line search cuts them to almost nothing; the barrier's gradient turns them away first.
  double barrier = 0.0;
  /// The barrier's value and its derivative in s, added to f and k (df/ds).
  void add_barrier(double s, double& f, double& k) const {
    if (barrier > 0.0) f -= barrier * std::log(s - floor), k -= barrier / (s - floor);
  }
  double operator()(const Vec3& e0, const Vec3& e1, const Vec3& e2, Vec3& g0, Vec3& g1, Vec3& g2,
                    double& s) const {
    const Vec3 d0 = e1.cross(e2), d1 = e2.cross(e0), d2 = e0.cross(e1);
    const double det = e0.dot(d0);
    const double a2 = e0.squaredNorm(), b2 = e1.squaredNorm(), c2 = e2.squaredNorm();
    const double pr = a2 * b2 * c2;
    const double l = std::sqrt(pr);
    if (!(l > 1e-300)) {
      s = -1.0;
      g0 = g1 = g2 = Vec3::Zero();
      return std::numeric_limits<double>::infinity();
    }
    // One division: 1/l = l / (a2 b2 c2) and 1/a2 = b2 c2 / (a2 b2 c2).
    const double inv_pr = 1.0 / pr, inv_l = l * inv_pr;
    s = det * inv_l;
    if (s <= floor) {
      g0 = g1 = g2 = Vec3::Zero();
      return std::numeric_limits<double>::infinity();
    }
    const double f1 = std::exp(beta * (s_ref - s));
    const double f2 = mean_weight != 0.0 ? mean_weight * std::exp(mean_beta * (s_ref - s)) : 0.0;
    double f = f1 + f2;
    double k = -beta * f1 - mean_beta * f2;  // df/ds
    add_barrier(s, f, k);
    const double kl = k * inv_l, ks = k * s * inv_pr;
    Vec3 w0, w1, w2;
    double wdet;
    const double fw = winslow(e0, e1, e2, w0, w1, w2, wdet);
    g0 = kl * d0 - (ks * b2 * c2) * e0 + mu * w0;
    g1 = kl * d1 - (ks * a2 * c2) * e1 + mu * w1;
    g2 = kl * d2 - (ks * a2 * b2) * e2 + mu * w2;
    return f + mu * fw;
  }

  /// The sum over the terms of one hex whose bit is set in `mask` (lane-parallel on HexTerms, as
  /// WinslowKernel::hex), the gradient added per local point into g; vmin receives the min s.
  /// +inf (and no gradient) when an active term is degenerate or at or below the floor.
  double hex(const Vec3 (&p)[8], unsigned mask, Vec3 (&g)[8], double& vmin) const {
    HexTerms t;
    t.load(p);
    double a2[kLanes], b2[kLanes], c2[kLanes], l[kLanes], inv_pr[kLanes], inv_l[kLanes], s[kLanes];
    t.squared_norms(0, a2), t.squared_norms(1, b2), t.squared_norms(2, c2);
    for (int i = 0; i < kLanes; ++i) {
      // One division: 1/l = l / (a2 b2 c2) and 1/a2 = b2 c2 / (a2 b2 c2).
      const double pr = a2[i] * b2[i] * c2[i];
      l[i] = std::sqrt(pr);
      inv_pr[i] = 1.0 / pr;
      inv_l[i] = l[i] * inv_pr[i];
      s[i] = l[i] > 1e-300 ? t.det[i] * inv_l[i] : -1.0;
    }
    bool bad = false;
    for (int i = 0; i < kHexTerms; ++i) {
      if (!(mask >> i & 1u)) continue;
      vmin = std::min(vmin, s[i]);
      bad |= !(l[i] > 1e-300) || s[i] <= floor;
    }
    if (bad) return std::numeric_limits<double>::infinity();
    double inv_c[kLanes], inv_r[kLanes], c23[kLanes];
    winslow.reciprocals_lanes(t.det, inv_c, inv_r);
    inv_cbrt_lanes(inv_c, c23);
    for (int i = 0; i < kLanes; ++i) c23[i] *= inv_c[i];
    // The exponentials (library calls) of the active terms only.
    double ex[kLanes], ex2[kLanes];
    for (int i = 0; i < kHexTerms; ++i) ex[i] = mask >> i & 1u ? std::exp(beta * (s_ref - s[i])) : 0.0;
    // The per-hex softmin's value and its derivatives in s (lane-parallel but for the sums).
    double soft_value = 0.0, soft_k[kLanes] = {};
    if (mean_softmin > 0.0 && mean_weight != 0.0) {
      double m = std::numeric_limits<double>::infinity(), z[kLanes] = {}, sum = 0.0;
      for (int i = 0; i < kHexTerms; ++i)
        if (mask >> i & 1u) m = std::min(m, s[i]);
      for (int i = 0; i < kHexTerms; ++i)
        if (mask >> i & 1u) z[i] = std::exp(-mean_softmin * (s[i] - m)), sum += z[i];
      if (sum > 0.0) {  // no active term: nothing to add
        soft_value = mean_weight * (std::log(sum) / mean_softmin - m);
        for (int i = 0; i < kLanes; ++i) soft_k[i] = -mean_weight * (z[i] / sum);
      }
      std::fill(std::begin(ex2), std::end(ex2), 0.0);
    } else {
      for (int i = 0; i < kHexTerms; ++i)
        ex2[i] = mean_weight != 0.0 && (mask >> i & 1u) ? mean_weight * std::exp(mean_beta * (s_ref - s[i])) : 0.0;
    }
    ex[kHexTerms] = ex2[kHexTerms] = 0.0;
    // term value; k = df/ds; the Winslow gradient's factors (k2 e_k + kd d_k, times mu)
    double value[kLanes], k[kLanes], wk2[kLanes], wkd[kLanes];
    for (int i = 0; i < kLanes; ++i) {
      double k2, kd;
      const double fw = winslow.finish((a2[i] + b2[i]) + c2[i], t.det[i], inv_c[i], inv_r[i], c23[i], k2, kd);
      value[i] = ex[i] + ex2[i] + mu * fw;
      k[i] = -beta * ex[i] - mean_beta * ex2[i] + soft_k[i];
      wk2[i] = mu * k2, wkd[i] = mu * kd;
    }
    double barrier_value[kLanes] = {};  // add_barrier, lane-parallel but for the logarithm
    if (barrier > 0.0) {
      for (int i = 0; i < kLanes; ++i) k[i] -= barrier / (s[i] - floor);
      for (int i = 0; i < kHexTerms; ++i)
        if (mask >> i & 1u) barrier_value[i] = barrier * std::log(s[i] - floor);
    }
    double a0[kLanes], a1[kLanes], a2k[kLanes], bk[kLanes];  // gradient a_k e_k + b d_k
    for (int i = 0; i < kLanes; ++i) {
      const double kl = k[i] * inv_l[i], ks = k[i] * s[i] * inv_pr[i];
      a0[i] = wk2[i] - ks * b2[i] * c2[i];
      a1[i] = wk2[i] - ks * a2[i] * c2[i];
      a2k[i] = wk2[i] - ks * a2[i] * b2[i];
      bk[i] = kl + wkd[i];
    }
    double f = soft_value;
    for (int i = 0; i < kHexTerms; ++i) {
      if (!(mask >> i & 1u)) continue;
      f += value[i];
      if (barrier > 0.0) f -= barrier_value[i];
    }
    t.scatter(mask, a0, a1, a2k, bk, g);
    return f;
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
