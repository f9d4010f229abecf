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
#include "geometry/untangle_newton.h"
#include "geometry/untangle_problem.h"
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

using namespace untangle_detail;

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