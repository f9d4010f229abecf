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
/// terms, in units of the
/// reference cube).
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
  /// Phase 1 minimizer. L-BFGS is the default: on every mesh measured (issue 6) it was faster than
  /// Newton, whose CHOLMOD factorizations of a 3D mesh's Hessian fill in heavily, and reached the
  /// same result.
  UntangleSolver solver = UntangleSolver::lbfgs;
  /// Phase 1 eps schedule. tracking: screw2 (4869 hexes) untangles in 39 rounds, where theorem
  /// keeps 358 hexes inverted after 20 rounds and 63 after 300 (issue 6).
  EpsRule eps_rule = EpsRule::tracking;
  int max_outer = 100;            ///< at most this many epsilon rounds in phase 1 (1..10000)
  /// Phase 1 also stops when the number of hexes with a non-positive corner or centre has not
  /// dropped for this many rounds (0: run all max_outer rounds while any is inverted).
  int stall_rounds = 20;
  /// When hexes stay inverted, retry by boundary continuation: untangle inside a smoothed copy
  /// of the boundary (morph_smoothing Laplacian steps of 1/2 over the boundary edges), then move
  /// the boundary back in morph_stages steps, untangling after each; the better of the two
  /// results is kept. 0 disables it. screw2 with --improve-budget 0: 169 hexes inverted
  /// directly, 0 by continuation; --side-rule heavier: 166 -> 0 (issue 6).
  int morph_stages = 10;
  int morph_smoothing = 100;      ///< boundary smoothing steps of the continuation (0..100000)
  /// At most this many phase 1 rounds per continuation step: bounds the time spent when the
  /// continuation cannot help either (screw2 --method original: 190 -> 172 inverted, 754 s with
  /// 100 rounds a step while CI ran alongside).
  int morph_step_rounds = 40;
  /// At most this many L-BFGS iterations per phase 1 round (fewer when the delta test below stops
  /// the run), 1..100000.
  int max_inner = 200;
  double inner_gtol = 1e-5;       ///< L-BFGS gradient tolerance, relative to |x| (> 0)
  /// The delta test: an L-BFGS run also stops once its energy fell by less than delta times |E|
  /// over the last inner_past iterations (LBFGSpp's test; delta 0 turns it off). inner_delta
  /// applies to phase 1's L-BFGS runs when phase 1 stops at the first untangled round (optimize
  /// and not relax_after_untangle), from the first point with every term positive,
  /// and to phase 2's mean polish; restart_delta to phase 2's restarts, which lift the worst
  /// corners and gain little per step. A tangled phase 1 run keeps all max_inner iterations
  /// (shorter rounds left screw2 inverted). Measured (issue 6, regularization 0.1): 10k-hex sphere 3.1 s ->
  /// 1.8 s, pierrot's untangling 36 s -> 22 s; on 79 surfaces the min SJ rose on 16 and fell on
  /// 11 (by at most 0.011); the mean rose by up to 0.005 and fell by at most 0.002.
  /// restart_delta 1e-5 (was 1e-6): a restart's energy is mostly the Winslow regularizer, so
  /// 1e-6 of it kept a run going long after its minimum had settled. Measured on 79 surfaces:
  /// phase 2 time about -25% (notched_fine 13.4 -> 9.1 s, plus_large 30.5 -> 23.1 s), min SJ
  /// higher on 12 and lower on 5 (pierrot 0.306 -> 0.298, the rest by < 0.001), mean higher on 4
  /// (pierrot 0.778 -> 0.783) and lower on 1 (by 0.0014). 3e-5 and 1e-4 lowered the min on 12
  /// and 17 surfaces.
  double inner_delta = 1e-4;
  double restart_delta = 1e-5;
  int inner_past = 10;            ///< iterations the delta test looks back (1..1000)
  double energy_rtol = 1e-5;      ///< phase 1 stops once all terms are positive and E changes by less
  /// Phase 1 stopping rule. false (default): when phase 2 runs, stop after the first round that
  /// leaves every term (corner, centre) positive; phase 2, whose objective includes the Winslow energy at
  /// eps ~ 0, does the rest of the relaxation. true (and always when optimize is false): keep
  /// lowering eps until E changes by less than energy_rtol (the papers' rule). On a 10k-hex
  /// jittered sphere that took 12 rounds and 9x the evaluations where the first round already
  /// untangled the mesh (issue 6).
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
  /// (the scaled Jacobian alone does not see size). Dimensionless, >= 0. 0.01 (was 0.1): the
  /// Winslow term pulled against the smoothed minimum; on 79 surfaces (issue 6) 0.01 raised the
  /// min SJ on 29 (pierrot 0.127 -> 0.306, plus_large 0.360 -> 0.479) and the mean on 32
  /// (screw2 0.518 -> 0.547); the min fell on one (by 0.001), the mean on one (rvox_s7, by 0.03,
  /// whose min rose 0.31 -> 0.47); the untangling stage took about 3x as long. 0.003 raised the
  /// min a little more but lowered the mean on 6 (star5 by 0.03); 0.1 kept for the mean polish
  /// alone lowered the mean on 32. With the final polish (final_polish_regularization), 0.003
  /// still trades: screw2 0.031 / 0.606 -> 0.049 / 0.602, pierrot 0.339 / 0.799 -> 0.362 /
  /// 0.784; on 77 surfaces min higher on 15, lower on 9, mean higher on 19, lower on 11
  /// (`--regularization`).
  double regularization = 0.01;
  /// Phase 2 then runs local max-min sweeps: the free vertices of the local_hexes worst hexes,
  /// worst first, each moved by a pattern search whose steps never lower the minimum of its hexes
  /// (sequential, deterministic; the global minimum never drops). With local_all, every other
  /// free vertex follows (in parallel by colours: no two vertices of a colour share a hex, so the
  /// result does not depend on the thread count); that mostly raises the mean (a mesh of at most
  /// local_hexes hexes has no other vertices). local_sweeps sweeps (0 or local_hexes 0 skips them
  /// all), then more, up to local_sweeps_max, while the last one raised the minimum scaled
  /// Jacobian of the hexes they see by local_sweep_min_gain or more, or their mean by
  /// local_sweep_mean_gain or more (both >= 0); a sweep that moves nothing ends them. Three sweeps
  /// alone (the earlier rule) left screw2's mean rising by 0.003 per sweep, while on smooth meshes
  /// the third sweep gains 1e-4 or less.
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
  /// times their mean (>= 0): a pure max-min (0) sacrificed the other hexes (thin plate: mean
  /// 0.55 -> 0.33).
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
  /// floor (the minimum the passes reached, which it therefore cannot lower), plus a log barrier
  /// final_polish_barrier (-log(s - s_min)) per term. Without the barrier the polish's L-BFGS
  /// steps keep hitting the floor and its line search cuts them to almost nothing (gear: 36
  /// iterations, 313 evaluations, then the delta test stops it). Up to final_polish_runs runs of
  /// at most max_mean_inner iterations each (max_mean_inner 0 skips it too), a further one (with
  /// a fresh L-BFGS memory) only when the last ran out of iterations, or its line search failed
  /// after moving the points; 0 runs skip it.
  /// It runs only when the mean sweeps follow: on its own it can lower that mean (its energy
  /// weighs every term, not each hex's worst: a pillowed voxel solid 0.7263 -> 0.7147 with
  /// regularization 0.01), and the mean sweeps climb higher from its point than from the
  /// passes' (there 0.7282 -> 0.7393). When they end below the mean the passes left (a 4x4
  /// cubed sphere: 0.9254 against 0.9274 in the mean of the hexes' worst active terms), the
  /// polish is dropped and the mean sweeps run again from the passes' point. That guard
  /// compares with the passes' mean before any mean sweep, not with what the mean sweeps alone
  /// would reach, so the mean can still end a little below the run without the polish (4 of the
  /// 77, by at most 0.0003, with regularization 0.01 in the polish; none with 0.002).
  /// On 77 generated and CAD-like surfaces (with final_polish_regularization 0.002): mean higher
  /// on 24 (gear 0.828 -> 0.903, gear_fine 0.856 -> 0.903, vase 0.964 -> 0.977), lower on none;
  /// minimum the same on 75, higher on 2 (the mean sweeps' own effect on it: disk 0.6152 ->
  /// 0.6159). pierrot 0.7911 -> 0.7989, screw2 0.5751 -> 0.6059, the same minima. The passes' own
  /// polish has no barrier: with one (0.01) the sweeps after it reached a lower minimum on 12 of
  /// 77 and a higher one on 7, and vase's mean fell 0.964 -> 0.956.
  int final_polish_runs = 3;
  double final_polish_barrier = 3e-3;  ///< > 0; <= 0 (or NaN) leaves the floor alone
  /// The final polish's weight of the Winslow regularizer (the passes use regularization). 0.002
  /// rather than 0.01: on 77 surfaces mean higher on 16 (gear 0.892 -> 0.903, gear_fine 0.892 ->
  /// 0.903, cylinder 0.941 -> 0.945), lower on 8 by at most 0.0004, the minimum the same on 74
  /// (higher on 2, lower on 1: gear_fine 0.3186 -> 0.3178, the mean sweeps' own effect);
  /// pierrot 0.7972 -> 0.7989, screw2 0.5864 -> 0.6059. 0.001 and 0.003 did about as well on
  /// three of them, 0.0003 and 0 worse (gear 0.868, 0.831).
  double final_polish_regularization = 2e-3;
  /// The final polish's mean term: with final_polish_softmin gamma > 0, each hex's softmin over
  /// its terms (QualityKernel::mean_softmin) weighed final_polish_softmin_weight, which lifts each
  /// hex's worst term, the one its scaled Jacobian is; 0 = the passes' flat per-term exponential
  /// (mean_beta, mean_weight), which lifts all nine terms alike. Against 0, on 61 generated,
  /// CAD-like and real surfaces: mean higher on 16 (pillowed voxel solids up to +0.008, a
  /// cylinder 0.8105 -> 0.8138), lower on 2 (10,400-hex cubed sphere 0.9826 -> 0.9815), minima
  /// the same but for 2 (by <= 0.0003); pierrot 0.7989 -> 0.8058, screw2 0.6162 -> 0.6211.
  /// Weights 4-7 gave pierrot 0.8054-0.8066 with all 3 runs made, but the delta test
  /// (inner_delta) can end the first run early, which left weights 4 and 8 at 0.791.
  double final_polish_softmin = 50.0;
  double final_polish_softmin_weight = 6.0;
  /// A final polish run that the delta test (inner_delta) ends is followed by another (up to
  /// final_polish_runs) unless it ended within inner_past iterations: that test can stop a run
  /// at a passing stall, which left pierrot's mean at 0.791 with softmin weights 4 and 8, 0.805
  /// and 0.801 with this (weight 6: 0.8058 either way). On 61 surfaces the polish then mostly
  /// makes one more run of about 10 iterations; means changed by at most 0.0003.
  bool final_polish_after_delta = true;
  /// Rounds of final polish and mean sweeps (>= 1): each further round starts from where the
  /// last left the points and is kept only if it raises the mean (over the hexes of their worst
  /// active term); the rounds stop at the first that does not, or when the first polish was not
  /// kept. 2 by default (was 1): on 67 generated, CAD-like and cubed-sphere surfaces the mean
  /// rose on 15 and fell on none (by at most 0.001: a pillowed voxel solid 0.7186 -> 0.7195),
  /// the minima the same; screw2 0.0685 / 0.6211 -> 0.0695 / 0.6359, pierrot 0.3387 / 0.8058 ->
  /// 0.3387 / 0.8069 (its published mesh: 0.222 / 0.806), for 5-20% more time on small meshes in
  /// alternating runs (a 10,400-hex cubed sphere 6.4 -> 6.8-7.3 s on a slow day) and about the
  /// same on pierrot. 3 rounds: pierrot 0.8071.
  int final_polish_rounds = 2;
  /// Phase 2 restarts (re-centred on the new minimum), 0..1000; they also stop once a restart
  /// raises the minimum corner s by less than 1e-3. 6 (was 4): with focus_width the restarts are
  /// cheap, and csphere_n12 still gained 0.005 in its 4th. 8 since restart_delta 1e-5 made each
  /// restart cheaper: large meshes keep gaining past the 6th (79 surfaces against 6 rounds and
  /// restart_delta 1e-6: min higher on 16, lower on 4 by at most 0.0004, mean higher on 6, lower
  /// on 2 by at most 0.0026; pierrot 0.306 / 0.778 -> 0.310 / 0.779, notched_fine 0.344 ->
  /// 0.353; 9% fewer corner evaluations). 10 rounds gained less than 0.01 more on 6 surfaces for
  /// another 4% and lowered pierrot's mean to 0.777.
  int max_quality_rounds = 8;
  /// The restarts also stop after one that runs all max_quality_inner iterations and raises the
  /// minimum by less than this (0 = off): a slow climb, which the sweeps and the next pass make
  /// for less. On a 10,400-hex equiangular cubed sphere restarts 4-8 each ran out of iterations
  /// for gains of 0.001-0.008 (1.2 s); stopping after the 4th gave the same minimum 0.7695 and
  /// mean 0.9827 -> 0.9826, `hexpeel mesh` 2.8 -> 1.8 s. On 61 generated, CAD-like and real
  /// surfaces it changed 3 (screw2 0.0575 / 0.6215 -> 0.0688 / 0.6162); pierrot's slow restarts
  /// gain more than this and it is unchanged.
  double restart_slow_gain = 5e-3;
  /// Phase 2 passes (>= 1): restarts, mean polish and max-min sweeps, repeated from where the
  /// sweeps left the points while a pass raises the minimum s over the active corner and centre
  /// terms by quality_pass_gain or more. A later pass is undone, and ends the passes, when it
  /// lowers that minimum, or when its gain in it plus local_mean_weight times its gain in the
  /// mean over the hexes of their minimum active term is negative. The mean sweeps run once,
  /// after the passes. quality_pass_gain 5e-3 rather than 1e-3 skipped third passes that gained
  /// little or were undone (10k-hex cubed sphere 3.4 -> 2.8 s; 75 of 77 surfaces unchanged).
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
