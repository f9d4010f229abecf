// Projected Newton for phase 1 of untangling: the sparse Hessian over the free vertices,
// assembled deterministically and factorized by CHOLMOD (internal to src/geometry).
#pragma once

#include "geometry/untangle_problem.h"

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCore>

namespace hexpeel::untangle_detail {

/// The assembled Hessian over the unknowns (upper triangle, CSC, as CHOLMOD wants) and its
/// factorization. The pattern and the symbolic analysis are computed once; every Newton iteration
/// refills the values and refactorizes. Assembly is deterministic without per-corner storage:
/// hexes (corner groups) are coloured so that two groups of one colour share no free vertex;
/// colours run in a fixed order, the groups of one colour in parallel, so every matrix entry
/// receives its contributions in the same order for any thread count.
struct NewtonSystem {
  Eigen::SparseMatrix<double> h;                  ///< 3nu x 3nu, upper triangle
  /// Per corner, per point pair (a <= b, kPairs order): the value index of the first row of the
  /// 3x3 block in each of its 3 columns, or -1 when a point is fixed. 
  std::vector<std::array<std::array<int32_t, 3>, 10>> corner_block;
  std::vector<std::array<uint8_t, 10>> corner_swap;  ///< block stored transposed (unknown a > b)
  std::vector<int32_t> color_start;               ///< groups of colour c: color_groups[cs[c], cs[c+1])
  std::vector<int32_t> color_groups;
  std::vector<int32_t> diag_index;                ///< value index of each diagonal entry
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Upper> supernodal;
  Eigen::CholmodSimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Upper> simplicial;
  bool use_supernodal = true;
  bool analyzed = false;

  static constexpr int kPairs[10][2] = {{0, 0}, {0, 1}, {0, 2}, {0, 3}, {1, 1},
                                        {1, 2}, {1, 3}, {2, 2}, {2, 3}, {3, 3}};

  void build(const Problem& prob, bool supernodal_mode) {
    use_supernodal = supernodal_mode;
    const int32_t nu = static_cast<int32_t>(prob.free_point.size()), nc = prob.num_corners();
    std::vector<Eigen::Triplet<double>> trip;
    trip.reserve(static_cast<size_t>(nc) * 45);
    for (const auto& k : prob.corners)
      for (const auto& pr : kPairs) {
        int32_t ua = prob.free_index[k[pr[0]]], ub = prob.free_index[k[pr[1]]];
        if (ua < 0 || ub < 0) continue;
        if (ua > ub) std::swap(ua, ub);
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            if (ua < ub || i <= j) trip.emplace_back(3 * ua + i, 3 * ub + j, 0.0);
      }
    h.resize(3 * nu, 3 * nu);
    h.setFromTriplets(trip.begin(), trip.end());
    h.makeCompressed();
    auto index_of = [&](int32_t row, int32_t col) {
      const int32_t* b = h.innerIndexPtr() + h.outerIndexPtr()[col];
      const int32_t* e = h.innerIndexPtr() + h.outerIndexPtr()[col + 1];
      const int32_t* it = std::lower_bound(b, e, row);
      HEXPEEL_ASSERT(it != e && *it == row);
      return static_cast<int32_t>(it - h.innerIndexPtr());
    };
    corner_block.assign(nc, {});
    corner_swap.assign(nc, {});
    for (int32_t c = 0; c < nc; ++c) {
      const auto& k = prob.corners[c];
      for (int p = 0; p < 10; ++p) {
        const int32_t ua = prob.free_index[k[kPairs[p][0]]], ub = prob.free_index[k[kPairs[p][1]]];
        auto& blk = corner_block[c][p];
        if (ua < 0 || ub < 0) {
          blk = {-1, -1, -1};
          continue;
        }
        const int32_t r = std::min(ua, ub), col = std::max(ua, ub);
        corner_swap[c][p] = ua > ub;
        for (int j = 0; j < 3; ++j) blk[j] = index_of(3 * r, 3 * col + j);
      }
    }
    diag_index.resize(3 * nu);
    for (int32_t i = 0; i < 3 * nu; ++i) diag_index[i] = index_of(i, i);
    // Greedy colouring of the corner groups by shared free vertices, in group order.
    const int32_t ng = static_cast<int32_t>(prob.group_start.size()) - 1;
    std::vector<int32_t> vg_start(nu + 1, 0), vg;
    auto for_free = [&](int32_t g, auto&& fn) {
      for (int32_t c = prob.group_start[g]; c < prob.group_start[g + 1]; ++c)
        for (int32_t v : prob.corners[c])
          if (prob.free_index[v] >= 0) fn(prob.free_index[v]);
    };
    for (int32_t g = 0; g < ng; ++g) for_free(g, [&](int32_t u) { ++vg_start[u + 1]; });
    for (int32_t u = 0; u < nu; ++u) vg_start[u + 1] += vg_start[u];
    vg.resize(vg_start[nu]);
    {
      std::vector<int32_t> fill(vg_start.begin(), vg_start.end() - 1);
      for (int32_t g = 0; g < ng; ++g) for_free(g, [&](int32_t u) { vg[fill[u]++] = g; });
    }
    std::vector<int32_t> color(ng, -1), seen;
    int32_t ncolors = 0;
    for (int32_t g = 0; g < ng; ++g) {
      for_free(g, [&](int32_t u) {
        for (int32_t i = vg_start[u]; i < vg_start[u + 1]; ++i) {
          const int32_t c = color[vg[i]];
          if (c >= 0) {
            if (c >= static_cast<int32_t>(seen.size())) seen.resize(c + 1, -1);
            seen[c] = g;
          }
        }
      });
      int32_t c = 0;
      while (c < static_cast<int32_t>(seen.size()) && seen[c] == g) ++c;
      color[g] = c;
      ncolors = std::max(ncolors, c + 1);
    }
    color_start.assign(ncolors + 1, 0);
    for (int32_t g = 0; g < ng; ++g) ++color_start[color[g] + 1];
    for (int32_t c = 0; c < ncolors; ++c) color_start[c + 1] += color_start[c];
    color_groups.resize(ng);
    std::vector<int32_t> fill(color_start.begin(), color_start.end() - 1);
    for (int32_t g = 0; g < ng; ++g) color_groups[fill[color[g]]++] = g;
    analyzed = false;
  }

  /// Fills the values with the projected Hessian of `kernel` at the current prob.pos.
  void assemble(const Problem& prob, const WinslowKernel& kernel) {
    double* val = h.valuePtr();
    std::fill(val, val + h.nonZeros(), 0.0);
    const int32_t ncolors = static_cast<int32_t>(color_start.size()) - 1;
    for (int32_t col = 0; col < ncolors; ++col)
      tbb::parallel_for(
          tbb::blocked_range<int32_t>(color_start[col], color_start[col + 1], 16),
          [&](const tbb::blocked_range<int32_t>& r) {
            Mat9 hf;
            Mat12 hc;
            for (int32_t i = r.begin(); i != r.end(); ++i) {
              const int32_t g = color_groups[i];
              for (int32_t c = prob.group_start[g]; c < prob.group_start[g + 1]; ++c) {
                const auto& k = prob.corners[c];
                const Vec3& p0 = prob.pos[k[0]];
                kernel.hessian(prob.pos[k[1]] - p0, prob.pos[k[2]] - p0, prob.pos[k[3]] - p0, hf, true);
                untangle_detail::corner_hessian(hf, hc);
                for (int p = 0; p < 10; ++p) {
                  const auto& blk = corner_block[c][p];
                  if (blk[0] < 0) continue;
                  const int a = kPairs[p][0], b = kPairs[p][1];
                  // Rows of the stored block come from point `ra`, columns from `cb`.
                  const int ra = corner_swap[c][p] ? b : a, cb = corner_swap[c][p] ? a : b;
                  for (int j = 0; j < 3; ++j)
                    for (int i = 0; i < (a == b ? j + 1 : 3); ++i)
                      val[blk[j] + i] += hc(3 * ra + i, 3 * cb + j);
                }
              }
            }
          });
  }

  /// Factorizes H + shift I; false when CHOLMOD finds it not positive definite.
  bool factorize(double shift) {
    if (shift != 0.0)
      for (int32_t i : diag_index) h.valuePtr()[i] += shift;
    auto run = [&](auto& solver) {
      if (!analyzed) solver.analyzePattern(h);
      analyzed = true;
      solver.factorize(h);
      return solver.info() == Eigen::Success;
    };
    const bool ok = use_supernodal ? run(supernodal) : run(simplicial);
    if (shift != 0.0)
      for (int32_t i : diag_index) h.valuePtr()[i] -= shift;
    return ok;
  }

  Eigen::VectorXd solve(const Eigen::VectorXd& b) {
    return use_supernodal ? Eigen::VectorXd(supernodal.solve(b)) : Eigen::VectorXd(simplicial.solve(b));
  }
};

struct NewtonRun {
  int iterations = 0, factorizations = 0;
  double solve_time_s = 0.0;
};

/// Projected Newton on the phase 1 energy from x, at most `max_iterations` steps: solve
/// (H + shift I) dx = -g, backtrack (Armijo) from the full step. The shift starts at a tiny
/// fraction of the mean diagonal (the clamped Hessian can be singular) and grows by 100 when the
/// factorization fails. Stops when a step gains less than rtol |E|, or no step is accepted.
NewtonRun newton(Problem& prob, NewtonSystem& sys, const WinslowKernel& kernel, Eigen::VectorXd& x,
                 const UntangleParams& p, int max_iterations);

}  // namespace hexpeel::untangle_detail
