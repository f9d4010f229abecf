// Untangling and quality optimization of a hex mesh's free (interior) vertices.
//
// Phase 1 (untangle): the regularized Winslow-type energy of Garanzha, Kaporin, Kudryavtseva,
// Protais, Ray and Sokolov ("Foldover-free maps in 50 lines of code", ACM TOG 2021; "Untangling and
// optimization of spatial meshes", 2022) on the 8 corner tetrahedra and the centre Jacobian of
// every hex (the 9 Jacobians of Verdict's scaled Jacobian), with epsilon continuation
// (UntangleParams::eps_rule), minimized by L-BFGS or by Newton's method (per-corner Hessians
// projected to positive semi-definite, sparse Cholesky by CHOLMOD), see UntangleParams::solver.
// Phase 1 stops once every term is positive (UntangleParams::relax_after_untangle), after
// max_outer rounds, or when the inverted count stalls (UntangleParams::stall_rounds).
// Phase 2 (optimize): a smoothed minimum of the 9 scaled Jacobians per hex, minimized by L-BFGS
// whose line search rejects any step that makes a term non-positive, so no hex positive after
// phase 1 goes <= 0; each restart moves only the vertices near the worst terms (focus_width).
// Fixed vertices never move (bit for bit).
// Same output for any thread count (fixed partitions, per-vertex sums in a fixed order).
#pragma once

#include "hexpeel/context.h"
#include "hexpeel/hex_mesh.h"
#include "hexpeel/status.h"

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

namespace hexpeel {

/// Minimizer of phase 1 (the Winslow energy). Phase 2 uses L-BFGS with either.
enum class UntangleSolver : uint8_t {
  newton,  ///< projected Newton: PSD-clamped corner Hessians, CHOLMOD factorization, backtracking
  lbfgs,   ///< L-BFGS (LBFGSpp): cheap iterations, many more of them
};
std::string_view to_string(UntangleSolver s);
/// "newton" or "lbfgs"; false (and `out` untouched) for anything else.
bool parse_untangle_solver(std::string_view name, UntangleSolver& out);

/// How phase 1 lowers eps between rounds (det below is the min det over the corner and centre
/// terms, in units of the reference cube).
enum class EpsRule : uint8_t {
  /// Garanzha et al. 2021, section 4: eps shrinks by a factor tied to the energy decrease, which
  /// the paper proves safe; it falls slowly (about 5% a round) while a corner sits near det = -1.
  theorem,
  /// eps = sqrt(eps_floor^2 + 0.04 det^2) while det <= 0 (eps follows a fifth of the worst
  /// corner's det), eps_floor once all are positive; eps_floor starts at 1e-3 and halves every
  /// 10 rounds. The rule the authors' own code uses by default.
  tracking,
};

std::string_view to_string(EpsRule r);

struct UntangleParams {
  bool untangle = true;   ///< run phase 1 (Winslow energy with epsilon continuation)
  bool optimize = true;   ///< run phase 2 (smoothed-min scaled Jacobian)
  /// Weight of the volume term (det^2 + 1) / chi against the shape term tr(J^T J) / chi^(2/3)
  /// (dimensionless, >= 0). det is measured against a cube of the mean hex volume.
  double lambda = 1.0;
  /// Phase 1 minimizer. L-BFGS by default: Newton's CHOLMOD factorizations of a 3D mesh's Hessian
  /// fill in heavily, which makes it slower for the same result.
  UntangleSolver solver = UntangleSolver::lbfgs;
  /// Phase 1 eps schedule (see EpsRule). tracking by default: it untangles hard meshes in far
  /// fewer rounds than theorem.
  EpsRule eps_rule = EpsRule::tracking;
  int max_outer = 100;            ///< at most this many epsilon rounds in phase 1 (1..10000)
  /// Phase 1 also stops when the number of hexes with a non-positive corner or centre has not
  /// dropped for this many rounds (0: run all max_outer rounds while any is inverted).
  int stall_rounds = 20;
  /// When hexes stay inverted, retry by boundary continuation: untangle inside a smoothed copy
  /// of the boundary (morph_smoothing Laplacian steps of 1/2 over the boundary edges), then move
  /// the boundary back in morph_stages steps, untangling after each; the better of the two
  /// results is kept. 0 disables it.
  int morph_stages = 10;
  int morph_smoothing = 100;      ///< boundary smoothing steps of the continuation (0..100000)
  /// At most this many phase 1 rounds per continuation step: bounds the time spent when the
  /// continuation cannot help either.
  int morph_step_rounds = 40;
  /// At most this many L-BFGS iterations per phase 1 round (fewer when the delta test below stops
  /// the run), 1..100000.
  int max_inner = 200;
  double inner_gtol = 1e-5;       ///< L-BFGS gradient tolerance, relative to |x| (> 0)
  /// The delta test: an L-BFGS run also stops once its energy fell by less than delta times |E|
  /// over the last inner_past iterations (LBFGSpp's test; 0 = off). inner_delta: phase 1's runs
  /// from the first all-positive point when phase 1 stops at the first untangled round (optimize
  /// and not relax_after_untangle), and phase 2's mean polish; a tangled phase 1 run keeps all
  /// max_inner iterations. restart_delta: phase 2's restarts, whose energy is mostly the Winslow
  /// regularizer, so a smaller delta keeps them running after their minimum has settled.
  double inner_delta = 1e-4;
  double restart_delta = 1e-5;
  int inner_past = 10;            ///< iterations the delta test looks back (1..1000)
  double energy_rtol = 1e-5;      ///< phase 1 stops once all terms are positive and E changes by less
  /// Phase 1 stopping rule. false (default): when phase 2 runs, stop after the first round that
  /// leaves every term (corner, centre) positive; phase 2, whose objective includes the Winslow energy at
  /// eps ~ 0, does the rest of the relaxation far more cheaply. true (and always when optimize is
  /// false): keep lowering eps until E changes by less than energy_rtol (the papers' rule).
  bool relax_after_untangle = false;
  int lbfgs_memory = 8;           ///< L-BFGS history length (1..100)
  int max_newton = 30;            ///< Newton iterations per epsilon round (1..10000)
  /// A Newton round ends when an iteration lowers E by less than this fraction of |E| (> 0).
  double newton_rtol = 1e-7;
  /// CHOLMOD factorization: supernodal (BLAS blocks) or simplicial (no BLAS). Same result up to
  /// rounding; the choice only matters for speed.
  bool supernodal = true;
  /// Phase 2 minimizes sum exp(beta * (s_min - s)) over the 9 scaled Jacobians s of every hex
  /// (8 corners and the centre): larger beta focuses harder on the worst ones (dimensionless, 1..200).
  double beta = 30.0;
  /// Phase 2 adds this times the phase 1 energy (eps ~ 0), which keeps edges from collapsing
  /// (the scaled Jacobian alone does not see size). Dimensionless, >= 0 (`--regularization`);
  /// kept small, since a heavier Winslow term pulls against the smoothed minimum.
  double regularization = 0.01;
  /// Phase 2 then runs local max-min sweeps: the free vertices of the local_hexes worst hexes,
  /// worst first, each moved by a pattern search whose steps never lower the minimum of its hexes
  /// (sequential, deterministic; the global minimum never drops). With local_all, every other
  /// free vertex follows (in parallel by colours: no two vertices of a colour share a hex, so the
  /// result does not depend on the thread count); that mostly raises the mean (a mesh of at most
  /// local_hexes hexes has no other vertices). local_sweeps sweeps (0 or local_hexes 0 skips them
  /// all), then more, up to local_sweeps_max, while the last one raised the minimum scaled
  /// Jacobian of the hexes they see by local_sweep_min_gain or more, or their mean by
  /// local_sweep_mean_gain or more (both >= 0); a sweep that moves nothing ends them.
  int local_sweeps = 3;
  int local_sweeps_max = 20;
  double local_sweep_min_gain = 1e-5;
  double local_sweep_mean_gain = 5e-4;
  int local_hexes = 200;
  bool local_all = true;
  /// The other vertices' searches stop at steps of this times their scale (the worst hexes'
  /// at 1e-3): coarser, since they are for the mean (in (0, 0.1]).
  double local_all_stop = 3e-2;
  /// With local_all, the sweeps end with mean sweeps: every free vertex, by colours, searched for
  /// the mean alone down to steps of this times its scale, while a sweep raises the mean by
  /// local_sweep_mean_gain or more (at most max(local_sweeps, local_sweeps_max) sweeps). A step
  /// never lowers the minimum of the vertex's own hexes, so the minimum the sweeps reached stays;
  /// like the other mean-only searches, they leave the vertices of hexes <= 0 where they are
  /// (0 skips them; (0, 0.1]).
  double local_polish_stop = 3e-3;
  /// A sweep step must keep the minimum of the vertex's hexes and raise that minimum plus this
  /// times their mean (>= 0; 0 = pure max-min, which sacrifices the other hexes' quality).
  double local_mean_weight = 1.0;
  /// Phase 2 ends with a mean polish over the whole mesh: the restarts' objective plus
  /// mean_weight exp(mean_beta (s_min - s)) per term, a flatter exponential that weighs every
  /// corner nearly alike and so raises the typical one; at most max_mean_inner L-BFGS iterations
  /// (0 skips it). It never lowers the minimum (see mean_pin). Dimensionless, > 0 / >= 0.
  double mean_beta = 2.0;
  double mean_weight = 1.0;
  int max_mean_inner = 100;
  /// The polish keeps every vertex of the hexes within this of the minimum where it is, and no
  /// other corner may reach the minimum (dimensionless, > 0).
  double mean_pin = 0.05;
  /// After the passes, before the mean sweeps, a final mean polish: the same energy, pinning and
  /// floor (the passes' minimum, which it cannot lower), plus final_polish_barrier times
  /// -log(s - s_min) per term, which keeps its L-BFGS steps off the floor (the passes' polish has
  /// no barrier). Up to final_polish_runs runs (0 skips it) of at most max_mean_inner iterations
  /// (0 skips it too); a further run, with fresh L-BFGS memory, only when the last ran out of
  /// iterations or its line search failed after moving the points. It runs only when the mean
  /// sweeps follow, and is dropped (the mean sweeps rerun from the passes' point) when they end
  /// below the mean the passes left.
  int final_polish_runs = 3;
  double final_polish_barrier = 3e-3;  ///< > 0; <= 0 (or NaN) leaves the floor alone
  /// The final polish's weight of the Winslow regularizer (dimensionless, >= 0; the passes use
  /// regularization). Lighter than the passes' so the polish can raise the mean further; much
  /// lighter (or 0) does worse.
  double final_polish_regularization = 2e-3;
  /// The final polish's mean term: with final_polish_softmin gamma > 0, each hex's softmin over
  /// its terms (QualityKernel::mean_softmin) weighed final_polish_softmin_weight, which lifts each
  /// hex's worst term, the one its scaled Jacobian is; 0 = the passes' flat per-term exponential
  /// (mean_beta, mean_weight), which lifts all nine terms alike.
  double final_polish_softmin = 50.0;
  double final_polish_softmin_weight = 6.0;
  /// A final polish run that the delta test (inner_delta) ends is followed by another (up to
  /// final_polish_runs) unless it ended within inner_past iterations: that test can stop a run
  /// at a passing stall. false: a run the delta test ends is the last.
  bool final_polish_after_delta = true;
  /// Rounds of final polish and mean sweeps (>= 1): each further round starts from where the
  /// last left the points and is kept only if it raises the mean (over the hexes of their worst
  /// active term); the rounds stop at the first that does not, or when the first polish was not
  /// kept. 2 by default: a second round still raises the mean on some meshes for a little more
  /// time; a third gains almost nothing.
  int final_polish_rounds = 2;
  /// Phase 2 restarts (re-centred on the new minimum), 0..1000; they also stop once a restart
  /// raises the minimum corner s by less than 1e-3. 8: focus_width and restart_delta make
  /// restarts cheap, and large meshes keep gaining past the 6th.
  int max_quality_rounds = 8;
  /// The restarts also stop after one that runs all max_quality_inner iterations and raises the
  /// minimum by less than this (0 = off): a slow climb, which the sweeps and the next pass make
  /// up for at less cost.
  double restart_slow_gain = 5e-3;
  /// Phase 2 passes (>= 1): restarts, mean polish and max-min sweeps, repeated from where the
  /// sweeps left the points while a pass raises the minimum s over the active corner and centre
  /// terms by quality_pass_gain or more. A later pass is undone, and ends the passes, when it
  /// lowers that minimum, or when its gain in it plus local_mean_weight times its gain in the
  /// mean over the hexes of their minimum active term is negative. The mean sweeps run once,
  /// after the passes. quality_pass_gain 5e-3 skips late passes that gain little or are undone.
  int quality_passes = 3;
  double quality_pass_gain = 5e-3;
  /// At most this many L-BFGS iterations per phase 2 restart (fewer when restart_delta stops the
  /// run), 1..100000.
  int max_quality_inner = 150;
  /// Phase 2 moves only the vertices near the worst corners: each restart frees the vertices of
  /// the hexes with a corner s < s_min + focus_width plus focus_rings rings of hexes around them
  /// and pins the rest. Corners above that weigh less than exp(-beta focus_width) in the smoothed
  /// minimum (exp(-9) with the defaults). Dimensionless; <= 0 optimizes the whole mesh each time.
  double focus_width = 0.3;
  int focus_rings = 2;            ///< rings of hexes added around the focus region (0..100)
  /// A corner whose 3 fixed points are collinear within this sine counts as forced (dimensionless).
  double collinear_tol = 1e-9;
};

struct UntanglePhaseStats {
  int32_t rounds = 0;        ///< outer rounds (epsilon updates / phase 2 restarts)
  /// L-BFGS iterations, summed over rounds; a run cut short (a line search failure, or phase 1
  /// switching to the delta test at its first untangled point) adds only its evaluations.
  int32_t iterations = 0;
  int32_t evaluations = 0;   ///< energy + gradient evaluations (of the whole mesh or a region)
  int64_t corner_evaluations = 0;  ///< corner and centre terms evaluated, summed over evaluations
  int32_t factorizations = 0;  ///< Newton: numeric Cholesky factorizations (0 for L-BFGS)
  double solve_time_s = 0.0;   ///< Newton: Hessian assembly + factorization + solves
  double time_s = 0.0;
  double min_sj_before = 0.0, min_sj_after = 0.0;  ///< min Verdict hex SJ over all hexes
  int32_t nonpositive_before = 0, nonpositive_after = 0;  ///< hexes with SJ <= 0
};

struct UntangleStats {
  UntangleSolver solver = UntangleSolver::lbfgs;  ///< phase 1 minimizer used
  EpsRule eps_rule = EpsRule::tracking;           ///< phase 1 eps schedule used
  bool stalled = false;  ///< phase 1 stopped because the inverted count stopped dropping
  bool continuation_run = false;   ///< the direct run left hexes inverted: continuation tried
  bool continuation_used = false;  ///< ... and its result was better, so it is the one returned
  int32_t direct_nonpositive = -1; ///< hexes <= 0 after the direct run (when continuation ran)
  int32_t direct_rounds = 0;       ///< phase 1 rounds of the direct run (when continuation ran)
  int32_t free_vertices = 0;
  int32_t active_corners = 0;   ///< corner tetrahedra in the energy (some point free)
  int32_t forced_corners = 0;   ///< left out: all 4 points fixed, or the fixed ones collinear
  int32_t forced_nonpositive = 0;  ///< forced corners with det <= 0: no placement fixes them
  /// The smallest scaled Jacobian (det of the unit edge vectors) of a forced corner: no placement
  /// of the free points can take the mesh's minimum above it. +infinity when there is none.
  double forced_min_sj = std::numeric_limits<double>::infinity();
  UntanglePhaseStats untangle, optimize;
  /// phase 2 ended with a lower minimum and ran again without its restarts (the only step that
  /// can lower it): polish and sweeps from the untangled points. local_moves, quality_passes and
  /// the final polish fields then count the second run only; the optimize phase stats both.
  bool optimize_restarts_dropped = false;
  /// the restarts of a pass stopped after one that ran out of iterations while gaining less than
  /// restart_slow_gain (and at least the 1e-3 that stops them anyway)
  bool restarts_ended_slow = false;
  bool optimize_reverted = false;  ///< phase 2 made the minimum worse and was undone
  bool mean_polish_kept = false;   ///< a mean polish of phase 2 ran and kept the minimum
  /// steps of phase 2's local sweeps (those of undone passes and of mean sweeps run again
  /// without the final polish left out)
  int64_t local_moves = 0;
  int32_t quality_passes = 0;      ///< phase 2 passes run (an undone last one included)
  int32_t final_polish_runs = 0;   ///< L-BFGS runs of the final mean polish (kept or not)
  /// the final mean polish ran, kept the minimum, and its point is the one the mean sweeps
  /// ended from (not dropped by the mean check)
  bool final_polish_kept = false;
  int32_t final_polish_rounds = 0;  ///< further rounds of polish and mean sweeps kept
  double final_eps = 0.0;
  double time_s = 0.0;
};

struct UntangleResult {
  Status status;     ///< ok, also when hexes stay inverted (see stats.untangle.nonpositive_after)
  HexMesh mesh;      ///< same hexes, free vertices moved
  UntangleStats stats;
};

/// `fixed[v]` != 0 pins vertex v (one entry per point). Hexes must be non-empty-positioned (finite).
UntangleResult run_untangle(const HexMesh& mesh, const std::vector<uint8_t>& fixed,
                            const UntangleParams& params = {}, const Context& ctx = {});

}  // namespace hexpeel
