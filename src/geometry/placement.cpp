// Initial placement of interior vertices: harmonic interpolation of the boundary.
//
// Boundary vertices are copied from the input surface. Interior vertices solve the uniform graph
// Laplacian over the complex's edges with the boundary fixed (a discrete harmonic map) by
// conjugate gradients. It is a start for the untangler, not a quality placement: concave shapes
// get inverted hexes. Coincident vertices are separated, since a placement that collapses
// vertices makes a valid complex look broken to point-merging readers.
#include "hexpeel/embedding.h"
#include "hexpeel/quality.h"

#include <Eigen/Geometry>
#include <Eigen/Sparse>
#include <Eigen/IterativeLinearSolvers>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>

namespace hexpeel {
namespace {

/// Pairs of points closer than tol (sorted by x, then compared within the tolerance window).
std::vector<std::pair<int32_t, int32_t>> coincident_pairs(const std::vector<Vec3>& P, double tol) {
  const int32_t n = static_cast<int32_t>(P.size());
  std::vector<int32_t> order(n);
  for (int32_t i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](int32_t a, int32_t b) {
    return std::tie(P[a].x(), P[a].y(), P[a].z(), a) < std::tie(P[b].x(), P[b].y(), P[b].z(), b);
  });
  std::vector<std::pair<int32_t, int32_t>> out;
  for (int32_t i = 0; i < n; ++i)
    for (int32_t j = i + 1; j < n && P[order[j]].x() - P[order[i]].x() <= tol; ++j)
      if ((P[order[j]] - P[order[i]]).norm() <= tol) out.push_back({order[i], order[j]});
  return out;
}

}  // namespace

Status harmonic_fill(const std::vector<Hex>& hexes, const std::vector<uint8_t>& fixed,
                     double tolerance, std::vector<Vec3>& points) {
  const int32_t nv = static_cast<int32_t>(points.size());
  std::vector<int32_t> unknown(nv, -1);
  int32_t nu = 0;
  for (int32_t v = 0; v < nv; ++v)
    if (!fixed[v]) unknown[v] = nu++;
  if (nu == 0) return Status::success();
  std::vector<uint64_t> edges;
  edges.reserve(12 * hexes.size());
  for (const Hex& h : hexes)
    for (const auto& e : kHexEdges) {
      int32_t a = h[e[0]], b = h[e[1]];
      if (a > b) std::swap(a, b);
      edges.push_back((static_cast<uint64_t>(a) << 32) | static_cast<uint32_t>(b));
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(nu, 3);
  std::vector<double> deg(nu, 0.0);
  for (uint64_t e : edges) {
    int32_t a = static_cast<int32_t>(e >> 32), b = static_cast<int32_t>(e & 0xffffffffu);
    for (auto [x, y] : {std::pair{a, b}, std::pair{b, a}}) {
      if (unknown[x] < 0) continue;
      deg[unknown[x]] += 1.0;
      if (unknown[y] >= 0)
        trip.emplace_back(unknown[x], unknown[y], -1.0);
      else
        rhs.row(unknown[x]) += points[y].transpose();
    }
  }
  for (int32_t i = 0; i < nu; ++i) {
    if (deg[i] == 0.0)
      return Status::error(StatusCode::internal_error, "placement: a free vertex has no edge");
    trip.emplace_back(i, i, deg[i]);
  }
  Eigen::SparseMatrix<double> L(nu, nu);
  L.setFromTriplets(trip.begin(), trip.end());
  // Conjugate gradients (diagonal preconditioner): a direct factorization of a 3D Laplacian
  // fills in badly (minutes and gigabytes at 100k hexes); CG needs only the matrix. The three
  // coordinates are independent solves, one solver each, run in parallel: each is single
  // threaded, hence deterministic.
  Eigen::MatrixXd x(nu, 3);
  std::array<bool, 3> converged{};
  tbb::parallel_for(0, 3, [&](int d) {
    Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper> solver;
    solver.setTolerance(tolerance);
    solver.setMaxIterations(std::max<int32_t>(1000, 10 * nu));
    solver.compute(L);
    x.col(d) = solver.solve(rhs.col(d));
    converged[d] = solver.info() == Eigen::Success;
  });
  if (!(converged[0] && converged[1] && converged[2]))
    return Status::error(StatusCode::internal_error, "placement: the Laplacian solve did not converge");
  for (int32_t v = 0; v < nv; ++v)
    if (unknown[v] >= 0) points[v] = x.row(unknown[v]).transpose();
  return Status::success();
}

PlacementResult run_placement(const QuadSurface& surface, const HexComplex& complex,
                              const PlacementParams& params, const Context& ctx) {
  const auto t0 = std::chrono::steady_clock::now();
  PlacementResult res;
  const int32_t nv = complex.num_vertices;
  res.mesh.hexes = complex.hexes;
  res.mesh.points.assign(nv, Vec3::Zero());
  std::vector<uint8_t> fixed(nv, 0);
  for (int32_t v = 0; v < nv; ++v)
    if (complex.input_vertex[v] >= 0) {
      res.mesh.points[v] = surface.points[complex.input_vertex[v]];
      fixed[v] = 1;
    }
  res.stats.interior_vertices = nv - static_cast<int32_t>(std::count(fixed.begin(), fixed.end(), 1));
  res.status = harmonic_fill(res.mesh.hexes, fixed, params.solver_tolerance, res.mesh.points);
  if (!res.status.ok()) return res;
  ctx.report("placement", 1.0);
  // Separate coincident vertices: a harmonic solve can put two interior vertices (or an interior
  // and a boundary one) on the same spot, e.g. at a degenerate hex, and point-merging readers
  // then see a broken complex. Each interior vertex of a coincident pair moves a little towards
  // the mean centroid of its hexes (boundary vertices never move).
  Eigen::AlignedBox3d box;
  for (const Vec3& p : surface.points) box.extend(p);
  const double tol = params.min_separation * std::max(box.diagonal().norm(), 1e-300);
  auto& P = res.mesh.points;
  for (int round = 0; round < 4; ++round) {
    std::vector<std::pair<int32_t, int32_t>> pairs = coincident_pairs(P, tol);
    if (round == 0) res.stats.coincident_pairs = static_cast<int32_t>(pairs.size());
    if (pairs.empty()) break;
    std::vector<uint8_t> move(nv, 0);
    for (auto [a, b] : pairs) {
      if (!fixed[a]) move[a] = 1;
      if (!fixed[b]) move[b] = 1;
    }
    std::vector<Vec3> target(nv, Vec3::Zero());
    std::vector<int32_t> count(nv, 0);
    for (const Hex& h : res.mesh.hexes) {
      Vec3 c = Vec3::Zero();
      for (int32_t v : h) c += P[v];
      c /= 8.0;
      for (int32_t v : h)
        if (move[v]) target[v] += c, ++count[v];
    }
    const double step = 1e-3 * box.diagonal().norm() * (round + 1);
    for (int32_t v = 0; v < nv; ++v) {
      if (!move[v] || count[v] == 0) continue;
      Vec3 d = target[v] / count[v] - P[v];
      double len = d.norm();
      // a fixed direction keeps the nudge deterministic when the centroid coincides too
      P[v] += len > tol ? Vec3(d * std::min(1.0, step / len)) : Vec3(step * Vec3(1, 2, 3).normalized() * (v % 7 + 1) / 7.0);
    }
  }
  res.stats.coincident_after = static_cast<int32_t>(coincident_pairs(P, tol).size());
  for (const Hex& h : res.mesh.hexes) {
    std::array<Vec3, 8> c;
    for (int k = 0; k < 8; ++k) c[k] = P[h[k]];
    if (scaled_jacobian(c) <= 0.0) ++res.stats.nonpositive_hexes;
  }
  res.stats.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

}  // namespace hexpeel
