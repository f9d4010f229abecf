// Untangling and scaled-Jacobian optimization of the free vertices of a hex mesh.
//
// Method: Garanzha, Kaporin, Kudryavtseva, Protais, Ray, Sokolov, "Foldover-free maps in 50 lines
// of code" (ACM TOG 2021, sections 3-4) and "Untangling and optimization of spatial meshes" (2022):
// every hex corner (corner c with its three frame neighbours, kHexCornerFrames) is a tetrahedron
// with Jacobian J = [e0 e1 e2] / h (e_k = p_{n_k} - p_c, h = a reference edge length, so a unit
// cube of edge h has J = I), and so is the hex centre (e_k = a quarter of principal axis k), the
// ninth Jacobian of Verdict's scaled Jacobian: with corners alone a hex can end with 8 positive
// corners and a negative centre (screw2: 144 hexes). Phase 1 minimizes
//     sum  tr(J^T J) / chi(det J, eps)^(2/3) + lambda (det^2 + 1) / chi(det J, eps),
//     chi(D, eps) = (D + sqrt(eps^2 + D^2)) / 2,
// with an epsilon update after each inner minimization (UntangleParams::eps_rule: by default eps
// tracks a fifth of the worst det, the rule of the authors' code; the paper's provable rule is
// the alternative) and a stall test (UntangleParams::stall_rounds); by default phase 1 ends at the first round that leaves every corner positive
// (UntangleParams::relax_after_untangle), its L-BFGS run relaxing from the first untangled
// point only until the energy flattens (the delta test, UntangleParams::inner_delta; phase 2's
// runs stop the same way), and phase 2 does the remaining relaxation. The inner
// minimizer is L-BFGS or projected Newton (UntangleParams::solver): the
// corner Hessians in closed form with negative eigenvalues clamped (untangle_kernels.h),
// assembled into a sparse matrix over the free vertices (corner terms only: the centre terms
// couple body-diagonal point pairs the corner pattern lacks, so their Hessians are left out and
// Newton is first order where a centre is the binding term), factorized by CHOLMOD (symbolic analysis
// once per run, numeric factorization per iteration), Armijo backtracking from the full step.
// Corners whose 4 points are all fixed, or whose fixed points are collinear, cannot change their
// sign: they are left out of the energy and out of the eps schedule (DESIGN.md "Geometry"),
// otherwise eps would never reach 0. Phase 2 minimizes sum exp(beta (s_min - s)) over the corner
// scaled Jacobians s = det / (|e0||e1||e2|) (a smoothed minimum); any trial point with a corner
// s <= 0 has energy +inf, so the line search never accepts an inverting step. Each phase 2
// restart moves only the vertices around the corners near the minimum (focus_width, focus_rings)
// and pins the rest, a much smaller problem on large meshes whose bad hexes are local.
// Evaluation runs hex by hex with batched kernels (untangle_kernels.h: the 8 corners' sqrt,
// division and cube root chains are independent, and the cube root is a few Newton steps, not
// libm's cbrt).
//
// Input: any hex mesh with finite points; `fixed` marks pinned vertices. Output: the same mesh
// with free vertices moved; fixed points are copied, never recomputed. Determinism: per-hex
// gradients are written to their own slots, energies summed over fixed blocks of hexes in block
// order, per-vertex gradients gathered in a fixed incidence order, the phase 2 regions chosen
// from those values alone, the Hessian assembled colour by colour
// (NewtonSystem), and CHOLMOD does not see the TBB thread count, so any thread count gives the
// same bytes.
#include "hexpeel/untangle.h"
#include "hexpeel/embedding.h"
#include "quality/quality_internal.h"
#include "geometry/untangle_kernels.h"
#include "hexpeel/quality.h"

#include <Eigen/CholmodSupport>
#include <Eigen/Geometry>
#include <Eigen/SparseCore>
#include <LBFGS.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <numeric>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>

namespace hexpeel {

std::string_view to_string(UntangleSolver s) {
  return s == UntangleSolver::newton ? "newton" : "lbfgs";
}

std::string_view to_string(EpsRule r) {
  return r == EpsRule::theorem ? "theorem" : "tracking";
}

bool parse_untangle_solver(std::string_view name, UntangleSolver& out) {
  if (name == "newton") out = UntangleSolver::newton;
  else if (name == "lbfgs") out = UntangleSolver::lbfgs;
  else return false;
  return true;
}

namespace {

using untangle_detail::chi;
using untangle_detail::Mat12;
using untangle_detail::Mat9;
using untangle_detail::QualityKernel;
using untangle_detail::WinslowKernel;
using Clock = std::chrono::steady_clock;
constexpr int32_t kBlock = 256;  // hexes per reduction block (fixed: keeps sums deterministic)

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// The optimization problem on flat arrays. Evaluation runs hex by hex (the 8 points loaded
/// once, the corners' gradients summed per hex into 8 slots), then gathers each unknown's slots.
struct Problem {
  std::vector<Vec3> base;                        ///< all points, scaled: (p - centre) / h
  std::vector<int32_t> free_index;               ///< point -> unknown index, -1 if fixed
  std::vector<int32_t> free_point;               ///< unknown index -> point
  std::vector<std::array<int32_t, 4>> corners;   ///< active corners: (c, n0, n1, n2) point ids
  std::vector<int32_t> group_start;              ///< corners of one hex: [group_start[i], [i+1])
  std::vector<Hex> hexes;                        ///< hexes with an active corner (group order)
  /// bit c: corner c of that hex is active; bit kCentre: its centre Jacobian is (some point free)
  std::vector<uint16_t> hex_mask;
  int32_t num_centres = 0;                       ///< hexes whose centre term is active
  std::vector<int32_t> inc_start;                ///< CSR over unknowns: slots 8*hex+k using it
  std::vector<int32_t> inc_slot;
  // work arrays (sized once, reused by every evaluation)
  std::vector<Vec3> pos;                         ///< current positions of all points
  std::vector<Vec3> hex_g;                       ///< gradient per hex and local point (8 slots)
  std::vector<double> block_sum;                 ///< per-block energy sums
  std::vector<double> block_min;                 ///< per-block min of det (phase 1) or s (phase 2)
  std::vector<int32_t> block_infinite;           ///< per block: its first hex of energy +inf, or -1
  /// Hexes whose energy was +inf at recent rejected trial points (at most kSuspects, the oldest
  /// replaced first): a trial point checks them before anything else, because the halved steps
  /// of one line search, and the next search's steps, are usually rejected by the same hexes.
  std::vector<int32_t> suspects;
  size_t next_suspect = 0;                       ///< the slot the next suspect replaces
  static constexpr size_t kSuspects = 32;
  int evaluations = 0;                           ///< energy + gradient evaluations so far
  int64_t corner_evaluations = 0;                ///< active corners times evaluations so far

  int32_t num_corners() const { return static_cast<int32_t>(corners.size()); }
  int32_t num_hexes() const { return static_cast<int32_t>(hexes.size()); }
  int32_t num_blocks() const { return (num_hexes() + kBlock - 1) / kBlock; }

  /// Sets up the incidence CSR and the work arrays once hexes / hex_mask are filled.
  void finish_setup() {
    const int32_t ng = num_hexes();
    const int32_t nu = static_cast<int32_t>(free_point.size());
    inc_start.assign(nu + 1, 0);
    for (const Hex& h : hexes)
      for (int32_t v : h)
        if (free_index[v] >= 0) ++inc_start[free_index[v] + 1];
    for (int32_t u = 0; u < nu; ++u) inc_start[u + 1] += inc_start[u];
    inc_slot.resize(inc_start[nu]);
    std::vector<int32_t> fill(inc_start.begin(), inc_start.end() - 1);
    for (int32_t g = 0; g < ng; ++g)
      for (int k = 0; k < 8; ++k) {
        const int32_t u = free_index[hexes[g][k]];
        if (u >= 0) inc_slot[fill[u]++] = 8 * g + k;
      }
    pos = base;
    hex_g.resize(8 * static_cast<size_t>(ng));
    block_sum.resize(num_blocks());
    block_min.resize(num_blocks());
    block_infinite.resize(num_blocks());
    suspects.clear();
    next_suspect = 0;
  }
  void set_positions(const Eigen::VectorXd& x) {
    for (size_t i = 0; i < free_point.size(); ++i) pos[free_point[i]] = x.segment<3>(3 * i);
  }

  /// Evaluates the sum of kernel.hex over the hexes (energy, per-hex gradients, block minima)
  /// and gathers the gradient per unknown. With `abandon_infinite` (a line search's trial point,
  /// which +inf only rejects), an evaluation whose energy is +inf stops early: it first checks
  /// the suspects, then skips the blocks not yet started and the rest of the block that found
  /// it, and does not gather the gradient, so block_min and the gradient are then incomplete
  /// (only +inf is returned). Whether the energy is +inf does not depend on the suspects or on
  /// the order the blocks run in, so neither changes a result.
  template <typename Kernel>
  double evaluate(const Eigen::VectorXd& x, Eigen::VectorXd& grad, const Kernel& kernel,
                  bool abandon_infinite = false) {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    ++evaluations;
    corner_evaluations += num_corners() + num_centres;
    set_positions(x);
    // kernel.hex of hex h at pos, its 8 point gradients into gh; m takes the min of its terms
    auto hex_energy = [&](int32_t h, Vec3 (&gh)[8], double& m) {
      Vec3 p[8];
      for (int k = 0; k < 8; ++k) p[k] = pos[hexes[h][k]], gh[k].setZero();
      return kernel.hex(p, hex_mask[h], gh, m);
    };
    if (abandon_infinite)
      for (int32_t h : suspects) {
        Vec3 gh[8];
        double m = kInf;
        if (hex_energy(h, gh, m) == kInf) return kInf;
      }
    const int32_t nb = num_blocks(), nh = num_hexes();
    std::atomic<bool> infinite{false};
    tbb::parallel_for(tbb::blocked_range<int32_t>(0, nb), [&](const tbb::blocked_range<int32_t>& r) {
      for (int32_t b = r.begin(); b != r.end(); ++b) {
        block_infinite[b] = -1;
        if (abandon_infinite && infinite.load(std::memory_order_relaxed)) {
          block_sum[b] = kInf;
          continue;
        }
        double s = 0.0, m = kInf;
        const int32_t end = std::min(nh, (b + 1) * kBlock);
        for (int32_t h = b * kBlock; h < end; ++h) {
          Vec3 gh[8];
          const double e = hex_energy(h, gh, m);
          s += e;
          for (int k = 0; k < 8; ++k) hex_g[8 * static_cast<size_t>(h) + k] = gh[k];
          if (e == kInf && block_infinite[b] < 0) {
            block_infinite[b] = h;
            if (abandon_infinite) break;
          }
        }
        block_sum[b] = s;
        block_min[b] = m;
        if (s == kInf) infinite.store(true, std::memory_order_relaxed);
      }
    });
    if (abandon_infinite && infinite.load(std::memory_order_relaxed)) {
      for (int32_t b = 0; b < nb; ++b)
        if (block_infinite[b] >= 0) {
          if (suspects.size() < kSuspects) {
            suspects.push_back(block_infinite[b]);
          } else {
            suspects[next_suspect] = block_infinite[b];
            next_suspect = (next_suspect + 1) % kSuspects;
          }
        }
      return kInf;
    }
    double total = 0.0;
    for (int32_t b = 0; b < nb; ++b) total += block_sum[b];
    const int32_t nu = static_cast<int32_t>(free_point.size());
    tbb::parallel_for(tbb::blocked_range<int32_t>(0, nu, 1024), [&](const tbb::blocked_range<int32_t>& r) {
      for (int32_t u = r.begin(); u != r.end(); ++u) {
        Vec3 g = Vec3::Zero();
        for (int32_t i = inc_start[u]; i < inc_start[u + 1]; ++i) g += hex_g[inc_slot[i]];
        grad.segment<3>(3 * u) = g;
      }
    });
    return total;
  }

  /// Per hex, the min scaled Jacobian of its active terms (corners, centre) at the current
  /// positions.
  void hex_min_value(std::vector<double>& out) const {
    out.resize(hexes.size());
    tbb::parallel_for(tbb::blocked_range<int32_t>(0, num_hexes(), 1024),
                      [&](const tbb::blocked_range<int32_t>& r) {
      for (int32_t h = r.begin(); h != r.end(); ++h) {
        Vec3 p[8];
        for (int k = 0; k < 8; ++k) p[k] = pos[hexes[h][k]];
        using untangle_detail::kLanes;
        untangle_detail::HexTerms t;
        t.load(p);
        double a2[kLanes], b2[kLanes], c2[kLanes];
        t.squared_norms(0, a2), t.squared_norms(1, b2), t.squared_norms(2, c2);
        double m = std::numeric_limits<double>::infinity();
        for (int i = 0; i < untangle_detail::kHexTerms; ++i) {
          if (!(hex_mask[h] >> i & 1u)) continue;
          const double l = std::sqrt(a2[i] * b2[i] * c2[i]);
          m = std::min(m, l > 1e-300 ? t.det[i] / l : -1.0);
        }
        out[h] = m;
      }
    });
  }

  /// Min over the active corners of det (phase 1) or s (phase 2) at the last evaluation.
  double min_corner_value() const {
    double m = std::numeric_limits<double>::infinity();
    for (double d : block_min) m = std::min(m, d);
    return m;
  }
};

/// Fills `prob` (whose `base` holds the scaled points) for the free vertices of `fixed`: the
/// active corners, grouped by hex (Newton assembly), and the evaluation layout. A corner whose 4
/// points are fixed, or whose 3 fixed points are collinear, cannot change its sign and is left
/// out; `forced` / `forced_nonpositive` (optional) count those and the ones with det <= 0, and
/// `forced_min` (optional) gets the smallest det of their unit edge vectors (-1 for a zero edge).
void build_problem(Problem& prob, const std::vector<Hex>& hexes, const std::vector<uint8_t>& fixed,
                   double collinear_tol, int32_t* forced, int32_t* forced_nonpositive,
                   double* forced_min = nullptr) {
  const int32_t np = static_cast<int32_t>(prob.base.size());
  prob.free_index.assign(np, -1);
  prob.free_point.clear();
  for (int32_t v = 0; v < np; ++v)
    if (!fixed[v]) {
      prob.free_index[v] = static_cast<int32_t>(prob.free_point.size());
      prob.free_point.push_back(v);
    }
  prob.corners.clear();
  prob.hexes.clear();
  prob.hex_mask.clear();
  prob.group_start.assign(1, 0);
  prob.num_centres = 0;
  for (const Hex& h : hexes) {
    uint16_t mask = 0;
    for (int c = 0; c < 8; ++c) {
      const std::array<int32_t, 4> k{h[c], h[kHexCornerFrames[c][0]], h[kHexCornerFrames[c][1]],
                                     h[kHexCornerFrames[c][2]]};
      int nfix = 0;
      std::array<int32_t, 4> fx{};
      for (int32_t v : k)
        if (fixed[v]) fx[nfix++] = v;
      bool is_forced = nfix == 4;
      if (nfix == 3) {
        const Vec3 a = prob.base[fx[1]] - prob.base[fx[0]], b = prob.base[fx[2]] - prob.base[fx[0]];
        is_forced = a.cross(b).norm() <= collinear_tol * a.norm() * b.norm();
      }
      if (is_forced) {
        if (forced) ++*forced;
        const Vec3 e0 = prob.base[k[1]] - prob.base[k[0]], e1 = prob.base[k[2]] - prob.base[k[0]],
                   e2 = prob.base[k[3]] - prob.base[k[0]];
        if (forced_nonpositive && e0.dot(e1.cross(e2)) <= 0.0) ++*forced_nonpositive;
        if (forced_min) {
          const double l = e0.norm() * e1.norm() * e2.norm();
          *forced_min = std::min(*forced_min, l > 0.0 ? e0.dot(e1.cross(e2)) / l : -1.0);
        }
      } else {
        prob.corners.push_back(k);
        mask |= static_cast<uint16_t>(1u << c);
      }
    }
    // The centre Jacobian depends on all 8 points: it can change unless all are fixed.
    bool any_free = false;
    for (int32_t v : h) any_free |= !fixed[v];
    if (any_free) {
      mask |= static_cast<uint16_t>(1u << untangle_detail::kCentre);
      ++prob.num_centres;
    }
    if (mask != 0) {
      prob.group_start.push_back(static_cast<int32_t>(prob.corners.size()));
      prob.hexes.push_back(h);
      prob.hex_mask.push_back(mask);
    }
  }
  prob.finish_setup();
}

/// When an L-BFGS run stops, besides its gradient test and iteration cap.
enum class StopRule : uint8_t {
  gradient,  ///< the gradient test and the iteration cap only
  /// also once E fell by less than `delta` times |E| over the last inner_past iterations
  delta,
  /// the gradient test while some term is <= 0; from the first point where every term is
  /// positive (min_corner_value() > 0), a fresh run with the delta test
  delta_once_positive,
};

/// Runs L-BFGS on `kernel` from x; x ends at the lowest finite energy seen (with
/// delta_once_positive, the lowest seen after the switch). `delta` <= 0 turns both delta rules
/// into `gradient`. Returns the iterations of the runs that ended normally (a run cut short by
/// a line search failure or by the switch counts 0; its evaluations are counted).
template <typename Kernel>
int minimize(Problem& prob, const Kernel& kernel, Eigen::VectorXd& x, const UntangleParams& p,
             int max_iterations, StopRule rule = StopRule::gradient, double delta = 0.0) {
  if (x.size() == 0) return 0;
  if (!(delta > 0.0)) rule = StopRule::gradient;
  LBFGSpp::LBFGSParam<double> lp;
  lp.m = p.lbfgs_memory;
  lp.epsilon = 1e-10;
  lp.epsilon_rel = p.inner_gtol;
  lp.max_iterations = max_iterations;
  lp.max_linesearch = 40;
  if (rule == StopRule::delta) {
    lp.past = std::clamp(p.inner_past, 1, 1000);
    lp.delta = delta;
  }
  struct Positive {};  // thrown by the first evaluation that finds every term positive
  LBFGSpp::LBFGSSolver<double> solver(lp);
  double best = std::numeric_limits<double>::infinity();
  Eigen::VectorXd best_x = x;
  const int evaluations_before = prob.evaluations;
  auto fun = [&](const Eigen::VectorXd& y, Eigen::VectorXd& g) {
    // A trial point with energy +inf is only rejected by the line search: its evaluation may
    // stop at the first infinite block (the callers re-evaluate at the returned x).
    const double f = prob.evaluate(y, g, kernel, /*abandon_infinite=*/true);
    if (rule == StopRule::delta_once_positive && std::isfinite(f) && prob.min_corner_value() > 0.0) {
      best_x = y;  // a line search trial may lie above the best energy seen: it is taken anyway
      throw Positive{};
    }
    if (std::isfinite(f) && f < best) {
      best = f;
      best_x = y;
    }
    return f;
  };
  int iters = 0;
  double fx = 0.0;
  try {
    iters = solver.minimize(fun, x, fx);
  } catch (const Positive&) {
    x = best_x;
    const int left = max_iterations - (prob.evaluations - evaluations_before);
    return left > 0 ? minimize(prob, kernel, x, p, left, StopRule::delta, delta) : 0;
  } catch (const std::exception&) {
    // Line search failures near the optimum or at the barrier: keep the best point seen (the
    // iterations of an interrupted run are not known; evaluations are counted instead).
    iters = 0;
  }
  if (std::isfinite(best)) x = best_x;
  return iters;
}

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
                 const UntangleParams& p, int max_iterations) {
  NewtonRun run;
  const int64_t n = x.size();
  Eigen::VectorXd g(n), gt(n), xt(n);
  double f = prob.evaluate(x, g, kernel);
  for (int it = 0; it < max_iterations; ++it) {
    const auto t0 = Clock::now();
    sys.assemble(prob, kernel);  // prob.pos holds x: evaluate() was last called at x
    double mean_diag = 0.0;
    for (int32_t i : sys.diag_index) mean_diag += sys.h.valuePtr()[i];
    mean_diag = std::max(mean_diag / std::max<int64_t>(1, n), 1e-300);
    double shift = 1e-10 * mean_diag;
    bool ok = false;
    for (int attempt = 0; attempt < 8 && !ok; ++attempt, shift *= 100.0) {
      ok = sys.factorize(shift);
      ++run.factorizations;
    }
    if (!ok) {
      run.solve_time_s += seconds_since(t0);
      break;
    }
    const Eigen::VectorXd dx = sys.solve(-g);
    run.solve_time_s += seconds_since(t0);
    const double slope = g.dot(dx);
    if (!(slope < 0.0)) break;
    double alpha = 1.0, ft = 0.0;
    bool accepted = false;
    for (int ls = 0; ls < 40; ++ls, alpha *= 0.5) {
      xt = x + alpha * dx;
      ft = prob.evaluate(xt, gt, kernel);
      if (std::isfinite(ft) && ft <= f + 1e-4 * alpha * slope) {
        accepted = true;
        break;
      }
    }
    if (!accepted) {
      prob.evaluate(x, g, kernel);  // leave prob.pos at x
      break;
    }
    ++run.iterations;
    const double gain = f - ft;
    x.swap(xt);
    g.swap(gt);
    f = ft;
    if (gain <= p.newton_rtol * std::abs(f)) break;
  }
  return run;
}

struct HexQuality {
  double min = 1.0;
  int32_t nonpositive = 0;
};

HexQuality hex_quality(const HexMesh& mesh) {
  HexQuality q;
  std::vector<double> sj(mesh.hexes.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, mesh.hexes.size(), 512),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t h = r.begin(); h != r.end(); ++h) {
                        std::array<Vec3, 8> c;
                        for (int k = 0; k < 8; ++k) c[k] = mesh.points[mesh.hexes[h][k]];
                        sj[h] = scaled_jacobian(c);
                      }
                    });
  for (double s : sj) {
    q.min = std::min(q.min, s);
    if (s <= 0.0) ++q.nonpositive;
  }
  return q;
}

}  // namespace

namespace {

/// Minimizes `kernel` over the free points of `prob` that `sub_fixed` leaves free, the others
/// pinned where x has them (prob.pos must hold x: evaluate() last called at x), at most
/// `iterations` L-BFGS iterations (and the delta test with `delta`, see StopRule), and writes
/// the result back into x. `sub` is reused storage.
/// Returns the number of points the region freed; adds the work to `st`.
int32_t minimize_region(Problem& prob, Problem& sub, const std::vector<uint8_t>& sub_fixed,
                        const QualityKernel& kernel, Eigen::VectorXd& x,
                        const UntangleParams& params, int iterations, double delta,
                        UntanglePhaseStats& st) {
  sub.base = prob.pos;
  build_problem(sub, prob.hexes, sub_fixed, params.collinear_tol, nullptr, nullptr);
  const int32_t ns = static_cast<int32_t>(sub.free_point.size());
  Eigen::VectorXd xs(3 * ns);
  for (int32_t u = 0; u < ns; ++u) xs.segment<3>(3 * u) = sub.base[sub.free_point[u]];
  const int ev_sub = sub.evaluations;
  const int64_t cev_sub = sub.corner_evaluations;
  st.iterations += minimize(sub, kernel, xs, params, iterations, StopRule::delta, delta);
  st.evaluations += sub.evaluations - ev_sub;
  st.corner_evaluations += sub.corner_evaluations - cev_sub;
  for (int32_t u = 0; u < ns; ++u)
    x.segment<3>(3 * prob.free_index[sub.free_point[u]]) = xs.segment<3>(3 * u);
  return ns;
}

/// Local max-min sweeps (UntangleParams::local_sweeps). Each sweep takes the free vertices of the
/// local_hexes hexes with the lowest scaled Jacobian, worst first, and moves each by a pattern
/// search over 14 directions (axes and diagonals) that accepts a step only when it keeps the
/// minimum scaled Jacobian of the vertex's hexes and raises that minimum plus local_mean_weight
/// times their mean; the step starts at a tenth of the vertex's mean distance to the other points
/// of its hexes and halves when no direction helps, down to 1/1000 of it. The smoothed
/// objectives spread their gradient over many corners; this one moves the worst hexes' vertices
/// directly. With local_all, every other free vertex follows, in parallel by colours (no two
/// vertices of a colour share a hex, so a vertex's search reads only hexes no other vertex of its
/// colour touches): the result is the same for any thread count. The global minimum never drops.
/// `max_min_sweeps` runs these sweeps, `mean_sweeps` the mean sweeps (local_polish_stop) after
/// them. Returns the moves.
int64_t local_max_min(const Problem& prob, std::vector<Vec3>& pts, const UntangleParams& params,
                      bool max_min_sweeps, bool mean_sweeps) {
  const std::vector<Hex>& hexes = prob.hexes;
  const int32_t nh = static_cast<int32_t>(hexes.size());
  const int32_t np = static_cast<int32_t>(pts.size());
  if (nh == 0 || params.local_sweeps <= 0 || params.local_hexes <= 0) return 0;
  // The hexes of free point v: slots inc_slot[i] / 8 for i in the range of its unknown.
  auto first = [&](int32_t v) { return prob.inc_start[prob.free_index[v]]; };
  auto last = [&](int32_t v) { return prob.inc_start[prob.free_index[v] + 1]; };
  auto hex_sj = [&](int32_t h) {
    std::array<Vec3, 8> c;
    for (int k = 0; k < 8; ++k) c[k] = pts[hexes[h][k]];
    return scaled_jacobian(c);
  };
  // While v moves, only v's point of each of its hexes changes, and only 5 of a hex's 9 scaled
  // Jacobian terms: the centre, v's corner k and the corners of k's 3 edge neighbours. A search
  // keeps, per hex of v, the hex's points (c[k] is v's, updated per trial) and the minimum of the
  // other 4 terms (a degenerate term is -2, below any value, so the minimum keeps it and equals
  // scaled_jacobian exactly, given 8 distinct points per hex, as reconstruction builds).
  struct HexOfVertex {
    std::array<Vec3, 8> c;
    int k;
    double rest;
  };
  auto hexes_of = [&](int32_t v, std::vector<HexOfVertex>& out) {
    out.resize(last(v) - first(v));
    for (int32_t i = first(v); i < last(v); ++i) {
      HexOfVertex& h = out[i - first(v)];
      h.k = prob.inc_slot[i] % 8;
      for (int j = 0; j < 8; ++j) h.c[j] = pts[hexes[prob.inc_slot[i] / 8][j]];
      const auto& nb = kHexCornerFrames[h.k];
      h.rest = std::numeric_limits<double>::infinity();
      for (int corner = 0; corner < 8; ++corner)
        if (corner != h.k && corner != nb[0] && corner != nb[1] && corner != nb[2])
          h.rest = std::min(h.rest, scaled_jacobian_term(h.c, 1 + corner));
    }
  };
  // The scaled Jacobian of hex h of v with v at p.
  auto hex_value = [&](HexOfVertex& h, const Vec3& p) {
    h.c[h.k] = p;
    const auto& nb = kHexCornerFrames[h.k];
    double q = h.rest;
    for (int term : {0, 1 + h.k, 1 + nb[0], 1 + nb[1], 1 + nb[2]})
      q = std::min(q, scaled_jacobian_term(h.c, term));
    return q == std::numeric_limits<double>::infinity() ? kDegenerateScaledJacobian : q;  // all NaN
  };
  // (min, mean) of the scaled Jacobians of v's hexes with v at p, and the hex of the minimum. A
  // trial whose minimum drops below `floor` is rejected whatever its mean, so the evaluation
  // stops at the first hex below it (then only `min < floor` is meaningful); hex `worst` (the
  // current minimum's, the likeliest to drop) is tried first. The mean sums in hex order.
  struct VertexQuality {
    double min, mean;
    int worst;
  };
  auto vertex_quality = [&](const Vec3& p, std::vector<HexOfVertex>& hs, int worst, double floor) {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    const double q_worst = worst >= 0 ? hex_value(hs[worst], p) : kInf;
    if (q_worst < floor) return VertexQuality{q_worst, 0.0, worst};
    VertexQuality out{kInf, 0.0, -1};
    double sum = 0.0;
    for (int i = 0; i < static_cast<int>(hs.size()); ++i) {
      const double q = i == worst ? q_worst : hex_value(hs[i], p);
      if (q < floor) return VertexQuality{q, 0.0, i};
      if (q < out.min) out.min = q, out.worst = i;
      sum += q;
    }
    out.mean = sum / std::max<size_t>(1, hs.size());
    return out;
  };
  // A step must not lower the minimum and must raise minimum + w * mean: w = local_mean_weight
  // for the worst hexes' vertices; the other vertices' steps are for the mean alone (kMeanOnly:
  // scoring their local minimum too lowered the mean).
  constexpr double kMeanOnly = -1.0;
  auto score = [&](const VertexQuality& q, double w) {
    return w == kMeanOnly ? q.mean : q.min + w * q.mean;
  };
  static const std::array<Vec3, 14> dirs = [] {
    std::array<Vec3, 14> d;
    int n = 0;
    for (int a = 0; a < 3; ++a)
      for (double sgn : {1.0, -1.0}) d[n++] = sgn * Vec3::Unit(a);
    for (int m = 0; m < 8; ++m)
      d[n++] = Vec3(m & 1 ? 1 : -1, m & 2 ? 1 : -1, m & 4 ? 1 : -1) / std::sqrt(3.0);
    return d;
  }();
  // The pattern search of one vertex, down to steps of stop times its scale; returns its moves.
  auto search = [&](int32_t v, double stop, double w) {
    double len = 0.0;
    int count = 0;
    for (int32_t i = first(v); i < last(v); ++i)
      for (int32_t u : hexes[prob.inc_slot[i] / 8])
        if (u != v) len += (pts[u] - pts[v]).norm(), ++count;
    const double l = count > 0 ? len / count : 0.0;
    std::vector<HexOfVertex> hs;
    hexes_of(v, hs);
    VertexQuality cur = vertex_quality(pts[v], hs, -1, -std::numeric_limits<double>::infinity());
    // A step may take any hex of v down to v's minimum: for the mean alone, not when that
    // minimum is a hex <= 0 (a forced corner, say), which would let the others follow it.
    if (w == kMeanOnly && !(cur.min > 0.0)) return 0;
    int32_t moved = 0;
    double step = 0.1 * l;
    for (int it = 0; it < 200 && step > stop * l; ++it) {
      const Vec3 old = pts[v];
      int best = -1;
      VertexQuality best_q = cur;
      for (int d = 0; d < 14; ++d) {
        const VertexQuality q = vertex_quality(old + step * dirs[d], hs, cur.worst, cur.min);
        if (q.min >= cur.min && score(q, w) > score(best_q, w)) best_q = q, best = d;
      }
      if (best >= 0) {
        pts[v] = old + step * dirs[best];
        cur = best_q;
        ++moved;
      } else {
        step *= 0.5;
      }
    }
    return moved;
  };
  std::vector<double> sj(nh);
  // The scaled Jacobians of all hexes into sj; their minimum and mean (summed in hex order: the
  // same for any thread count).
  auto measure = [&](double& sj_min, double& sj_mean) {
    tbb::parallel_for(tbb::blocked_range<int32_t>(0, nh, 512),
                      [&](const tbb::blocked_range<int32_t>& r) {
                        for (int32_t h = r.begin(); h != r.end(); ++h) sj[h] = hex_sj(h);
                      });
    sj_min = *std::min_element(sj.begin(), sj.end());
    sj_mean = std::accumulate(sj.begin(), sj.end(), 0.0) / nh;
  };
  // The free vertices without skip[v], coloured greedily in id order so that no two of a colour
  // share a hex, sorted by colour (stable); color[v] receives v's colour.
  std::vector<int32_t> color(np, -1), moved;
  std::vector<uint8_t> used;
  auto colour = [&](const std::vector<uint8_t>& skip) {
    std::vector<int32_t> verts;
    std::fill(color.begin(), color.end(), -1);
    int32_t colors = 0;
    for (int32_t v = 0; v < np; ++v) {
      if (prob.free_index[v] < 0 || skip[v]) continue;
      used.assign(colors + 1, 0);
      for (int32_t j = first(v); j < last(v); ++j)
        for (int32_t w : hexes[prob.inc_slot[j] / 8])
          if (color[w] >= 0) used[color[w]] = 1;
      int32_t c = 0;
      while (used[c]) ++c;
      color[v] = c;
      colors = std::max(colors, c + 1);
      verts.push_back(v);
    }
    std::stable_sort(verts.begin(), verts.end(),
                     [&](int32_t a, int32_t b) { return color[a] < color[b]; });
    return verts;
  };
  // Searches the vertices of `verts` group after group (group(i) is verts[i]'s; each group a
  // run of equal values, the runs in order), the vertices of one group in parallel: no two of a
  // group may share a hex, so each reads only hexes no other one moves. Returns the moves.
  auto search_groups = [&](const std::vector<int32_t>& verts, auto&& group, double stop, double w) {
    moved.assign(verts.size(), 0);
    for (size_t b = 0; b < verts.size();) {
      size_t e = b;
      while (e < verts.size() && group(e) == group(b)) ++e;
      tbb::parallel_for(tbb::blocked_range<size_t>(b, e, 4),
                        [&](const tbb::blocked_range<size_t>& r) {
                          for (size_t i = r.begin(); i != r.end(); ++i)
                            moved[i] = search(verts[i], stop, w);
                        });
      b = e;
    }
    return std::accumulate(moved.begin(), moved.end(), int64_t{0});
  };
  // Searches the vertices of `verts` (sorted by colour) for the mean alone, down to steps of
  // `stop` times their scale, colour after colour.
  auto sweep_colours = [&](const std::vector<int32_t>& verts, double stop) {
    return search_groups(verts, [&](size_t i) { return color[verts[i]]; }, stop, kMeanOnly);
  };
  // Searches the vertices of `verts` in their order, as one after the other would, but in
  // parallel where that gives the same result: a search reads and moves only points of its
  // vertex's hexes, so a vertex that shares no hex with an earlier one still to run may run
  // now. A vertex's level is one above the highest level of the earlier vertices it shares a
  // hex with (0 when there are none), so two of one level share no hex; the levels run in
  // order. Returns the moves.
  std::vector<int32_t> hex_level(nh), level, by_level;
  auto search_in_order = [&](const std::vector<int32_t>& verts, double stop, double w) {
    const size_t n = verts.size();
    std::fill(hex_level.begin(), hex_level.end(), -1);
    level.resize(n);
    for (size_t j = 0; j < n; ++j) {
      int32_t l = 0;
      for (int32_t i = first(verts[j]); i < last(verts[j]); ++i)
        l = std::max(l, hex_level[prob.inc_slot[i] / 8] + 1);
      level[j] = l;
      for (int32_t i = first(verts[j]); i < last(verts[j]); ++i) hex_level[prob.inc_slot[i] / 8] = l;
    }
    by_level.resize(n);
    std::iota(by_level.begin(), by_level.end(), 0);
    std::stable_sort(by_level.begin(), by_level.end(),
                     [&](int32_t a, int32_t b) { return level[a] < level[b]; });
    std::vector<int32_t> ordered(n);
    for (size_t i = 0; i < n; ++i) ordered[i] = verts[by_level[i]];
    return search_groups(ordered, [&](size_t i) { return level[by_level[i]]; }, stop, w);
  };
  std::vector<uint8_t> in_worst(np, 0);
  int64_t moves = 0;
  double last_min = 0.0, last_mean = 0.0;
  const int max_sweeps = std::max(params.local_sweeps, params.local_sweeps_max);
  for (int sweep = 0; max_min_sweeps && sweep < max_sweeps; ++sweep) {
    double sj_min, sj_mean;
    measure(sj_min, sj_mean);
    if (sweep >= params.local_sweeps && sj_min - last_min < params.local_sweep_min_gain &&
        sj_mean - last_mean < params.local_sweep_mean_gain)
      break;
    last_min = sj_min, last_mean = sj_mean;
    std::vector<int32_t> order(nh);
    std::iota(order.begin(), order.end(), 0);
    const int32_t k = std::min(nh, params.local_hexes);
    std::partial_sort(order.begin(), order.begin() + k, order.end(), [&](int32_t a, int32_t b) {
      return sj[a] != sj[b] ? sj[a] < sj[b] : a < b;
    });
    // 1. The free vertices of the k worst hexes, worst hex first, one after the other: each sees
    // the moves before it (moving them in parallel lowered the minimum on pierrot and screw2);
    // search_in_order runs the independent ones side by side, with the same result.
    std::vector<int32_t> verts;
    std::fill(in_worst.begin(), in_worst.end(), 0);
    for (int32_t i = 0; i < k; ++i)
      for (int32_t v : hexes[order[i]])
        if (prob.free_index[v] >= 0 && !in_worst[v]) in_worst[v] = 1, verts.push_back(v);
    int64_t sweep_moves = 0;
    sweep_moves += search_in_order(verts, 1e-3, params.local_mean_weight);
    // 2. With local_all, every other free vertex, by colours.
    if (params.local_all) sweep_moves += sweep_colours(colour(in_worst), params.local_all_stop);
    moves += sweep_moves;
    if (sweep_moves == 0) break;
  }
  // 3. The mean sweeps: every free vertex, by colours, with finer steps, while the mean rises.
  // Their steps never lower a vertex's own minimum, so the minimum reached above stays.
  if (mean_sweeps && params.local_all && params.local_polish_stop > 0.0) {
    const std::vector<int32_t> verts = colour(std::vector<uint8_t>(np, 0));
    measure(last_min, last_mean);
    for (int sweep = 0; sweep < max_sweeps; ++sweep) {
      const int64_t sweep_moves = sweep_colours(verts, params.local_polish_stop);
      moves += sweep_moves;
      double sj_min, sj_mean;
      measure(sj_min, sj_mean);
      if (sweep_moves == 0 || sj_mean - last_mean < params.local_sweep_mean_gain) break;
      last_mean = sj_mean;
    }
  }
  return moves;
}

/// Phase 1 and phase 2 from the given positions (run_untangle without the continuation).
UntangleResult untangle_once(const HexMesh& mesh, const std::vector<uint8_t>& fixed,
                             const UntangleParams& params, const Context& ctx) {
  const auto t_start = Clock::now();
  UntangleResult res;
  res.mesh = mesh;
  const int32_t np = mesh.num_points();
  if (static_cast<int32_t>(fixed.size()) != np) {
    res.status = Status::error(StatusCode::internal_error, "untangle: fixed mask size != points");
    return res;
  }
  const HexQuality q0 = hex_quality(mesh);
  res.stats.untangle.min_sj_before = res.stats.untangle.min_sj_after = q0.min;
  res.stats.untangle.nonpositive_before = res.stats.untangle.nonpositive_after = q0.nonpositive;

  // Scale: centre on the bounding box, unit = mean length of fixed-fixed hex edges (the boundary
  // quads' edges), or of all edges when nothing is fixed.
  Problem prob;
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& p : mesh.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const Vec3 centre = np > 0 ? Vec3(0.5 * (lo + hi)) : Vec3::Zero();
  double len_fixed = 0.0, len_all = 0.0;
  int64_t n_fixed = 0, n_all = 0;
  for (const Hex& h : mesh.hexes)
    for (const auto& e : kHexEdges) {
      const double l = (mesh.points[h[e[0]]] - mesh.points[h[e[1]]]).norm();
      len_all += l, ++n_all;
      if (fixed[h[e[0]]] && fixed[h[e[1]]]) len_fixed += l, ++n_fixed;
    }
  double unit = n_fixed > 0 ? len_fixed / n_fixed : (n_all > 0 ? len_all / n_all : 1.0);
  if (!(unit > 0.0) || !std::isfinite(unit)) unit = 1.0;
  prob.base.resize(np);
  for (int32_t v = 0; v < np; ++v) prob.base[v] = (mesh.points[v] - centre) / unit;

  int32_t forced = 0, forced_nonpositive = 0;
  double forced_min = std::numeric_limits<double>::infinity();
  build_problem(prob, mesh.hexes, fixed, params.collinear_tol, &forced, &forced_nonpositive,
                &forced_min);
  const int32_t nu = static_cast<int32_t>(prob.free_point.size()), nc = prob.num_corners();
  res.stats.solver = params.solver;
  res.stats.eps_rule = params.eps_rule;
  res.stats.free_vertices = nu;
  res.stats.forced_corners = forced;
  res.stats.forced_nonpositive = forced_nonpositive;
  res.stats.forced_min_sj = forced_min;
  res.stats.active_corners = nc;
  if (nu == 0 || prob.num_hexes() == 0) {
    res.stats.time_s = seconds_since(t_start);
    res.stats.optimize.min_sj_before = res.stats.optimize.min_sj_after = q0.min;
    res.stats.optimize.nonpositive_before = res.stats.optimize.nonpositive_after = q0.nonpositive;
    return res;
  }

  Eigen::VectorXd x(3 * nu), g(3 * nu);
  for (int32_t u = 0; u < nu; ++u) x.segment<3>(3 * u) = prob.base[prob.free_point[u]];
  auto write_back = [&](const Eigen::VectorXd& y) {
    for (int32_t u = 0; u < nu; ++u)
      res.mesh.points[prob.free_point[u]] = centre + unit * Vec3(y.segment<3>(3 * u));
  };

  // ---- Phase 1: untangle (Winslow energy, epsilon continuation) ----
  if (params.untangle) {
    const auto t1 = Clock::now();
    const int ev0 = prob.evaluations;
    const int64_t cev0 = prob.corner_evaluations;
    WinslowKernel k{1.0, params.lambda};
    prob.evaluate(x, g, k);
    double detmin = prob.min_corner_value();
    // eps_floor: the tracking rule's eps once every corner is positive, halved every 10 rounds.
    double eps_floor = 1e-3;
    auto tracking_eps = [&] {
      return detmin > 0 ? eps_floor : std::sqrt(eps_floor * eps_floor + 0.04 * detmin * detmin);
    };
    if (params.eps_rule == EpsRule::tracking) k.eps = tracking_eps();
    else k.eps = detmin > 0 ? 1e-10 : 1.0;
    NewtonSystem sys;
    if (params.solver == UntangleSolver::newton) sys.build(prob, params.supernodal);
    // Stall test state: the fewest hexes with a non-positive term seen after a round, the
    // positions then, the count after the last round and the checked rounds since the best.
    std::vector<double> hex_s;
    Eigen::VectorXd x_best;
    int32_t best_bad = std::numeric_limits<int32_t>::max(), last_bad = -1;
    int since_best = 0;
    for (int round = 0; round < params.max_outer; ++round) {
      const double e_prev = prob.evaluate(x, g, k);
      if (params.solver == UntangleSolver::newton) {
        const NewtonRun nr = newton(prob, sys, k, x, params, params.max_newton);
        res.stats.untangle.iterations += nr.iterations;
        res.stats.untangle.factorizations += nr.factorizations;
        res.stats.untangle.solve_time_s += nr.solve_time_s;
      } else {
        // When phase 2 follows, the round that untangles relaxes only until E flattens.
        const bool relax_briefly = params.optimize && !params.relax_after_untangle;
        res.stats.untangle.iterations +=
            minimize(prob, k, x, params, params.max_inner,
                     relax_briefly ? StopRule::delta_once_positive : StopRule::gradient,
                     params.inner_delta);
      }
      const double e = prob.evaluate(x, g, k);
      detmin = prob.min_corner_value();
      ++res.stats.untangle.rounds;
      ctx.report("untangle", std::min(1.0, (round + 1.0) / params.max_outer));
      if (detmin > 0 && std::abs(e_prev - e) <= params.energy_rtol * std::abs(e)) break;
      // Untangled: phase 2 (whose objective includes this energy at eps ~ 0) takes over.
      if (detmin > 0 && !params.relax_after_untangle && params.optimize) break;
      last_bad = -1;
      if (detmin <= 0 && params.stall_rounds > 0) {
        // Stalled: the count of hexes with a non-positive term has not dropped for stall_rounds.
        prob.hex_min_value(hex_s);
        last_bad = static_cast<int32_t>(
            std::count_if(hex_s.begin(), hex_s.end(), [](double v) { return v <= 0.0; }));
        if (last_bad < best_bad) {
          best_bad = last_bad, since_best = 0;
          x_best = x;
        } else if (++since_best >= params.stall_rounds) {
          res.stats.stalled = true;
          break;
        }
      }
      if (params.eps_rule == EpsRule::tracking) {
        if ((round + 1) % 10 == 0 && eps_floor > 1e-8) eps_floor *= 0.5;
        k.eps = tracking_eps();
      } else {
        const double sigma = std::max(1.0 - e / e_prev, 0.1);
        const double mu = (1.0 - sigma) * chi(detmin, k.eps);
        k.eps = detmin < mu ? 2.0 * std::sqrt(mu * (mu - detmin)) : 1e-10;
      }
    }
    if (last_bad > best_bad) {  // ended inverted and worse than the best round: go back there
      x = x_best;
      prob.evaluate(x, g, k);
    }
    res.stats.final_eps = k.eps;
    res.stats.untangle.evaluations = prob.evaluations - ev0;
    res.stats.untangle.corner_evaluations = prob.corner_evaluations - cev0;
    write_back(x);
    const HexQuality q1 = hex_quality(res.mesh);
    res.stats.untangle.min_sj_after = q1.min;
    res.stats.untangle.nonpositive_after = q1.nonpositive;
    res.stats.untangle.time_s = seconds_since(t1);
  }

  // ---- Phase 2: raise the minimum corner scaled Jacobian, never crossing s <= 0 ----
  res.stats.optimize.min_sj_before = res.stats.untangle.min_sj_after;
  res.stats.optimize.nonpositive_before = res.stats.untangle.nonpositive_after;
  res.stats.optimize.min_sj_after = res.stats.optimize.min_sj_before;
  res.stats.optimize.nonpositive_after = res.stats.optimize.nonpositive_before;
  if (params.optimize) {
    const auto t2 = Clock::now();
    const int ev0 = prob.evaluations;
    const int64_t cev0 = prob.corner_evaluations;
    const Eigen::VectorXd x_before = x;
    QualityKernel k{params.beta, 0.0, 0.0, params.regularization, WinslowKernel{1e-10, params.lambda}};
    k.floor = -std::numeric_limits<double>::infinity();
    prob.evaluate(x, g, k);
    double smin = prob.min_corner_value();
    const bool focus = params.focus_width > 0.0;
    Problem sub;
    std::vector<uint8_t> in_region;
    std::vector<double> hex_s;
    // Sweeps on the points of x: the max-min sweeps and / or the mean sweeps.
    const bool sweeps = params.local_sweeps > 0 && params.local_hexes > 0;
    auto run_sweeps = [&](bool max_min_sweeps, bool mean_sweeps) {
      std::vector<Vec3> pts = prob.base;
      const int32_t nu = static_cast<int32_t>(prob.free_point.size());
      for (int32_t u = 0; u < nu; ++u) pts[prob.free_point[u]] = x.segment<3>(3 * u);
      res.stats.local_moves += local_max_min(prob, pts, params, max_min_sweeps, mean_sweeps);
      for (int32_t u = 0; u < nu; ++u) x.segment<3>(3 * u) = pts[prob.free_point[u]];
    };
    // The mean over the hexes of their minimum term at the last evaluation's points.
    auto mean_hex_value = [&] {
      prob.hex_min_value(hex_s);
      return std::accumulate(hex_s.begin(), hex_s.end(), 0.0) / std::max<size_t>(1, hex_s.size());
    };
    // Restarts (re-centred on the new minimum) from x until one gains less than 1e-3; pass and
    // passes place the progress report.
    auto run_restarts = [&](int pass, int passes) {
      for (int round = 0; round < params.max_quality_rounds; ++round) {
        const int32_t iterations_before = res.stats.optimize.iterations;
        k.s_ref = smin;
        // Positive meshes stay positive; a mesh with inverted corners may not get worse.
        k.floor = smin > 0 ? 0.0 : smin - 1e-12;
        if (focus) {
          // Only corners with s < s_ref + focus_width weigh in the smoothed minimum (the others'
          // exp terms are below exp(-beta focus_width)): free the vertices of their hexes and
          // focus_rings rings of hexes around them, pin the rest where it is.
          prob.hex_min_value(hex_s);
          in_region.assign(prob.base.size(), 0);
          for (int32_t h = 0; h < prob.num_hexes(); ++h)
            if (hex_s[h] < smin + params.focus_width)
              for (int32_t v : prob.hexes[h]) in_region[v] = 1;
          for (int ring = 0; ring < params.focus_rings; ++ring) {
            std::vector<uint8_t> grown = in_region;
            for (const Hex& h : prob.hexes) {
              bool touches = false;
              for (int32_t v : h) touches |= in_region[v] != 0;
              if (touches)
                for (int32_t v : h) grown[v] = 1;
            }
            in_region.swap(grown);
          }
          std::vector<uint8_t> sub_fixed(prob.base.size(), 1);
          for (int32_t v : prob.free_point) sub_fixed[v] = in_region[v] ? 0 : 1;
          minimize_region(prob, sub, sub_fixed, k, x, params, params.max_quality_inner,
                          params.restart_delta, res.stats.optimize);
        } else {
          res.stats.optimize.iterations += minimize(prob, k, x, params, params.max_quality_inner,
                                                    StopRule::delta, params.restart_delta);
        }
        prob.evaluate(x, g, k);
        const double s = prob.min_corner_value();
        ++res.stats.optimize.rounds;
        ctx.report("optimize", (pass + (round + 1.0) / params.max_quality_rounds) / passes);
        // Done when a restart gains little, or gains less than restart_slow_gain in all of its
        // iterations: the sweeps and the next pass lift such a slow climb for less.
        const double gain = s - smin;
        const bool slow = res.stats.optimize.iterations - iterations_before >=
                              params.max_quality_inner && gain < params.restart_slow_gain;
        smin = std::max(smin, s);
        if (gain < 1e-3) break;
        if (slow) {
          res.stats.restarts_ended_slow = true;
          break;
        }
      }
    };
    // Mean polish: the restarts' objective plus a flat exponential that weighs every corner
    // nearly alike. The hexes within mean_pin of the minimum keep all 8 vertices where they are,
    // every other corner must stay above the minimum, and the polish is undone if the minimum
    // still ends lower. `barrier` adds the kernel's log barrier at that floor, `mu` weighs the
    // Winslow regularizer; `softmin` > 0 makes the mean term each hex's softmin
    // (QualityKernel::mean_softmin) weighed `softmin_weight`; up to `runs` L-BFGS runs while one
    // ends unconverged (`after_delta`: see below). Sets `kept` when the result stays; returns the
    // runs made.
    auto run_polish = [&](double barrier, double mu, double softmin, double softmin_weight,
                          int runs, bool after_delta, bool& kept) {
      if (runs <= 0 || params.max_mean_inner <= 0 || !(params.mean_weight > 0.0) ||
          !(params.mean_pin > 0.0) || !(smin > 0.0))
        return 0;
      const Eigen::VectorXd x_min = x;
      const double s_now = prob.min_corner_value();  // at x (a last restart may have lost a bit)
      prob.hex_min_value(hex_s);
      std::vector<uint8_t> sub_fixed(prob.base.size(), 1);
      for (int32_t v : prob.free_point) sub_fixed[v] = 0;
      for (int32_t h = 0; h < prob.num_hexes(); ++h)
        if (hex_s[h] < s_now + params.mean_pin)
          for (int32_t v : prob.hexes[h]) sub_fixed[v] = 1;
      QualityKernel km = k;
      km.s_ref = s_now;
      km.floor = s_now;  // the hexes it evaluates start at >= s_now + mean_pin (the rest pinned)
      km.mean_beta = params.mean_beta;
      km.mean_weight = softmin > 0.0 ? softmin_weight : params.mean_weight;
      km.mean_softmin = softmin;
      km.barrier = barrier;
      km.mu = mu;
      int32_t ns = 0;
      int made = 0;
      while (made < runs) {
        const int32_t iterations_before = res.stats.optimize.iterations;
        const Eigen::VectorXd x_run = x;
        ns = minimize_region(prob, sub, sub_fixed, km, x, params, params.max_mean_inner,
                             params.inner_delta, res.stats.optimize);
        const int32_t iterations = res.stats.optimize.iterations - iterations_before;
        ++made;
        prob.evaluate(x, g, k);  // also the positions the next run's region starts from
        if (runs > 1) ctx.report("polish", static_cast<double>(made) / runs);
        // Converged (the delta or gradient test), or stuck where it started: done. Out of
        // iterations, or a line search failure after some progress (0 iterations counted):
        // another run, with a fresh L-BFGS memory.
        // With `after_delta`, a run the delta test ended early goes on too, unless it made no
        // more than the test's window of iterations (a stall, not a pause).
        if (x == x_run) break;
        if (after_delta ? iterations > 0 && iterations <= params.inner_past
                        : iterations > 0 && iterations < params.max_mean_inner)
          break;
      }
      kept = ns > 0 && prob.min_corner_value() >= s_now;
      if (!kept) {
        x = x_min;
        prob.evaluate(x, g, k);
      }
      return made;
    };
    // Passes: restarts, mean polish, max-min sweeps. A later pass starts the restarts from where
    // the sweeps left the points; it is undone if it ends with a lower minimum, or lowers the
    // mean more than it raises the minimum (weighed as the sweeps weigh them, local_mean_weight),
    // and the passes stop once one raises the minimum by less than quality_pass_gain.
    // A point to come back to: x, the mean hex value there (prob.pos must hold x), and the
    // sweeps' move count and mean_polish_kept, which an undo restores with it.
    struct Checkpoint {
      Eigen::VectorXd x;
      double mean = 0.0;
      int64_t moves = 0;
      bool mean_polish_kept = false;
    };
    auto checkpoint = [&] {
      return Checkpoint{x, mean_hex_value(), res.stats.local_moves, res.stats.mean_polish_kept};
    };
    auto restore = [&](const Checkpoint& c) {
      x = c.x, res.stats.local_moves = c.moves, res.stats.mean_polish_kept = c.mean_polish_kept;
    };
    // The passes and the final polish and mean sweeps, from x. Only the restarts can lower the
    // minimum (their floor is 0, not the minimum): `restarts` false leaves them out.
    auto optimize_from = [&](bool restarts) {
      const int passes = std::max(1, params.quality_passes);
      Checkpoint at_pass;
      for (int pass = 0; pass < passes; ++pass) {
        const double s_pass = smin;
        if (pass > 0) at_pass = checkpoint();
        if (restarts) run_restarts(pass, passes);
        bool polish_kept = false;
        run_polish(0.0, k.mu, 0.0, 0.0, 1, false, polish_kept);
        res.stats.mean_polish_kept |= polish_kept;
        if (sweeps) run_sweeps(true, false);
        prob.evaluate(x, g, k);
        const double s_end = prob.min_corner_value();
        ++res.stats.quality_passes;
        if (pass > 0 && (s_end < s_pass || (s_end - s_pass) + params.local_mean_weight *
                                                  (mean_hex_value() - at_pass.mean) < 0.0)) {
          restore(at_pass);
          prob.evaluate(x, g, k);
          break;
        }
        smin = s_end;
        if (s_end - s_pass < params.quality_pass_gain) break;
      }
      // The final polish only prepares the mean sweeps (see final_polish_runs). When the mean
      // sweeps from its point end below the mean the passes left, they run again from there.
      const bool mean_sweeps = sweeps && params.local_all && params.local_polish_stop > 0.0;
      if (mean_sweeps) {
        auto final_polish = [&](bool& kept) {
          return run_polish(params.final_polish_barrier, params.final_polish_regularization,
                            params.final_polish_softmin, params.final_polish_softmin_weight,
                            params.final_polish_runs, params.final_polish_after_delta, kept);
        };
        const Checkpoint at_passes = checkpoint();
        res.stats.final_polish_runs = final_polish(res.stats.final_polish_kept);
        run_sweeps(false, true);
        if (res.stats.final_polish_kept) {
          prob.evaluate(x, g, k);
          if (mean_hex_value() < at_passes.mean) {
            restore(at_passes);
            res.stats.final_polish_kept = false;
            run_sweeps(false, true);
          }
        }
        // Further rounds of polish and mean sweeps, each from where the last left the points,
        // kept while one raises the mean.
        for (int round = 1; round < params.final_polish_rounds && res.stats.final_polish_kept;
             ++round) {
          prob.evaluate(x, g, k);
          const Checkpoint at_round = checkpoint();
          bool kept = false;
          res.stats.final_polish_runs += final_polish(kept);
          if (!kept) break;
          run_sweeps(false, true);
          prob.evaluate(x, g, k);
          if (!(mean_hex_value() > at_round.mean)) {
            restore(at_round);
            break;
          }
          ++res.stats.final_polish_rounds;
        }
      }
    };
    const UntangleStats at_start = res.stats;  // what a run without the restarts starts from
    optimize_from(true);
    res.stats.optimize.evaluations += prob.evaluations - ev0;
    res.stats.optimize.corner_evaluations += prob.corner_evaluations - cev0;
    HexMesh before = res.mesh;
    write_back(x);
    HexQuality q2 = hex_quality(res.mesh);
    auto worse = [&] {
      return q2.min < res.stats.optimize.min_sj_before ||
             q2.nonpositive > res.stats.optimize.nonpositive_before;
    };
    if (worse()) {
      // The restarts left the minimum lower and nothing recovered it: everything again from the
      // untangled points without them (the polish and the sweeps, which keep the minimum), so
      // the mean still gains.
      const UntanglePhaseStats both_runs = res.stats.optimize;
      res.stats = at_start;
      res.stats.optimize = both_runs;
      res.stats.optimize_restarts_dropped = true;
      const int ev1 = prob.evaluations;
      const int64_t cev1 = prob.corner_evaluations;
      x = x_before;
      k.floor = -std::numeric_limits<double>::infinity();
      k.s_ref = 0.0;
      prob.evaluate(x, g, k);
      smin = prob.min_corner_value();
      optimize_from(false);
      res.stats.optimize.evaluations += prob.evaluations - ev1;
      res.stats.optimize.corner_evaluations += prob.corner_evaluations - cev1;
      write_back(x);  // every free point, so nothing of the first run's stays
      q2 = hex_quality(res.mesh);
    }
    if (worse()) {
      res.mesh = std::move(before);
      res.stats.optimize_reverted = true;
      res.stats.mean_polish_kept = false;
      res.stats.final_polish_kept = false;
      res.stats.final_polish_rounds = 0;
    } else {
      res.stats.optimize.min_sj_after = q2.min;
      res.stats.optimize.nonpositive_after = q2.nonpositive;
    }
    res.stats.optimize.time_s = seconds_since(t2);
  }
  res.stats.time_s = seconds_since(t_start);
  return res;
}

/// Boundary continuation (UntangleParams::morph_stages): the fixed vertices on the mesh's
/// boundary faces are smoothed (uniform Laplacian over the boundary edges, morph_smoothing
/// steps of 1/2), which fills pockets and holes; the free vertices are placed harmonically
/// inside that smoother shape and untangled there; then the boundary moves back to its true
/// position in morph_stages equal steps, phase 1 untangling after each from where the last one
/// ended. The last step puts every fixed vertex back bit for bit. Gives up (nullopt) as soon as
/// the start or a step leaves more hexes inverted than its share of `give_up_above` (the direct
/// run's count times the fraction of the way done): later steps only squeeze harder, so such a
/// run rarely beats the direct one, and this bounds the time spent on forced cases.
std::optional<UntangleResult> untangle_by_continuation(const HexMesh& mesh,
                                                       const std::vector<uint8_t>& fixed,
                                                       const UntangleParams& params,
                                                       int32_t give_up_above, const Context& ctx) {
  const int32_t np = mesh.num_points();
  std::vector<std::vector<int32_t>> adj(np);
  for (const Quad& q : quality_detail::analyze_topology(mesh).boundary_quads)  // faces used by one hex
    for (int k = 0; k < 4; ++k) {
      const int32_t a = q[k], b = q[(k + 1) % 4];
      if (fixed[a] && fixed[b]) adj[a].push_back(b), adj[b].push_back(a);
    }
  for (auto& a : adj) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  }
  HexMesh m = mesh;
  std::vector<Vec3> smooth(mesh.points);
  for (int it = 0; it < params.morph_smoothing; ++it) {
    std::vector<Vec3> next = smooth;
    for (int32_t v = 0; v < np; ++v) {
      if (adj[v].empty()) continue;
      Vec3 c = Vec3::Zero();
      for (int32_t w : adj[v]) c += smooth[w];
      next[v] = 0.5 * (smooth[v] + c / static_cast<double>(adj[v].size()));
    }
    smooth.swap(next);
  }
  m.points = smooth;
  if (!harmonic_fill(m.hexes, fixed, 1e-10, m.points).ok()) return std::nullopt;
  UntangleParams p = params;
  p.optimize = false;
  UntangleResult r = untangle_once(m, fixed, p, ctx);
  // Each step starts close to untangled; a step that needs many rounds is likely a forced case,
  // so the steps get a shorter round budget (the rescued screw2 plans needed 3-27 per step).
  p.max_outer = std::min(params.max_outer, params.morph_step_rounds);
  for (int s = 1; s <= params.morph_stages; ++s) {
    // Steps s-1 of morph_stages done: give up once the inverted count exceeds that share of the
    // direct run's (the successful runs measured stay at 0 all the way).
    const double share = static_cast<double>(s - 1) / params.morph_stages;
    if (!r.status.ok() || r.stats.untangle.nonpositive_after > share * give_up_above)
      return std::nullopt;
    const double t = static_cast<double>(s) / params.morph_stages;
    m = r.mesh;
    for (int32_t v = 0; v < np; ++v)
      if (fixed[v]) m.points[v] = s == params.morph_stages ? mesh.points[v]
                                                           : Vec3((1.0 - t) * smooth[v] + t * mesh.points[v]);
    if (s == params.morph_stages) p.optimize = params.optimize;
    r = untangle_once(m, fixed, p, ctx);
  }
  if (!r.status.ok()) return std::nullopt;
  return r;
}

}  // namespace

UntangleResult run_untangle(const HexMesh& mesh, const std::vector<uint8_t>& fixed,
                            const UntangleParams& params, const Context& ctx) {
  const auto t0 = Clock::now();
  UntangleResult direct = untangle_once(mesh, fixed, params, ctx);
  if (!direct.status.ok() || !params.untangle || params.morph_stages <= 0 ||
      direct.stats.untangle.nonpositive_after == 0)
    return direct;
  // Hexes stayed inverted: the start may have folded the mesh through the boundary (a harmonic
  // placement puts interior vertices into pockets of concave shapes), which local minimization
  // cannot undo. Retry by continuation and keep whichever result is better.
  ctx.report("untangle", 1.0);
  const int32_t direct_bad = direct.stats.untangle.nonpositive_after;
  const int32_t direct_rounds = direct.stats.untangle.rounds;
  std::optional<UntangleResult> cont =
      untangle_by_continuation(mesh, fixed, params, direct_bad, ctx);
  const bool better = cont && (cont->stats.optimize.nonpositive_after <
                                   direct.stats.optimize.nonpositive_after ||
                               (cont->stats.optimize.nonpositive_after ==
                                    direct.stats.optimize.nonpositive_after &&
                                cont->stats.optimize.min_sj_after > direct.stats.optimize.min_sj_after));
  UntangleResult& out = better ? *cont : direct;
  out.stats.continuation_run = true;
  out.stats.continuation_used = better;
  out.stats.direct_nonpositive = direct_bad;
  out.stats.direct_rounds = direct_rounds;
  out.stats.untangle.nonpositive_before = direct.stats.untangle.nonpositive_before;
  out.stats.untangle.min_sj_before = direct.stats.untangle.min_sj_before;
  out.stats.time_s = seconds_since(t0);
  return std::move(out);
}

}  // namespace hexpeel
