// The optimization problem of untangle.cpp on flat arrays, its L-BFGS driver and the helpers the
// phases share (internal to src/geometry; the method is described in untangle.cpp).
#pragma once

#include "hexpeel/hex_mesh.h"
#include "hexpeel/untangle.h"
#include "geometry/untangle_kernels.h"

#include <Eigen/Core>
#include <LBFGS.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace hexpeel::untangle_detail {

using Clock = std::chrono::steady_clock;
constexpr int32_t kBlock = 256;  // hexes per reduction block (fixed: keeps sums deterministic)

inline double seconds_since(Clock::time_point t0) {
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
                   double* forced_min = nullptr);

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

struct HexQuality {
  double min = 1.0;
  int32_t nonpositive = 0;
};

/// The minimum scaled Jacobian of the mesh's hexes and the count of those <= 0.
HexQuality hex_quality(const HexMesh& mesh);

/// Minimizes `kernel` over the free points of `prob` that `sub_fixed` leaves free, the others
/// pinned where x has them (prob.pos must hold x: evaluate() last called at x), at most
/// `iterations` L-BFGS iterations (and the delta test with `delta`, see StopRule), and writes
/// the result back into x. `sub` is reused storage.
/// Returns the number of points the region freed; adds the work to `st`.
int32_t minimize_region(Problem& prob, Problem& sub, const std::vector<uint8_t>& sub_fixed,
                        const QualityKernel& kernel, Eigen::VectorXd& x,
                        const UntangleParams& params, int iterations, double delta,
                        UntanglePhaseStats& st);

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
                      bool max_min_sweeps, bool mean_sweeps);

}  // namespace hexpeel::untangle_detail
