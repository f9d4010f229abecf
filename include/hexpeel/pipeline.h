// The whole meshing job on a surface already read: check, chords, elimination, reconstruction,
// placement, quality. The CLI is a thin shell around run_mesh (reading and writing files is its
// job, so it can time them and pick file names).
#pragma once

#include "hexpeel/diagnosis.h"
#include "hexpeel/elimination.h"
#include "hexpeel/planner.h"
#include "hexpeel/embedding.h"
#include "hexpeel/intrusion_cover.h"
#include "hexpeel/io.h"
#include "hexpeel/pillow.h"
#include "hexpeel/quality.h"
#include "hexpeel/reconstruction.h"
#include "hexpeel/surface_repair.h"
#include "hexpeel/tet_fill.h"
#include "hexpeel/terminal.h"
#include "hexpeel/untangle.h"

#include <nlohmann/json.hpp>

namespace hexpeel {

struct MeshParams {
  double sharp_angle_deg = 60.0;  ///< deviation from flat (degrees, in (0, 180)) that makes an edge sharp
  ValidationParams validation;
  EliminationParams elimination;  ///< its `order` rules serve the planner too
  /// A surface with a chord that crosses itself or an odd quad count is refined into one
  /// without (surface_repair.h) and that is meshed: the mesh's boundary is the repaired
  /// surface. Off: such a surface is refused.
  bool repair_surface = false;
  /// How the repaired surface is filled: tets = the surface split into six everywhere, filled
  /// through tetrahedra (tet_fill.h); elimination = the refined surface (split into six around
  /// the self-crossings, into four elsewhere) by dual cycle elimination, then the one split into
  /// six everywhere when that mesh keeps hexes <= 0; both = elimination and tets, the better
  /// mesh kept (better_result).
  enum class RepairFill { tets, elimination, both };
  RepairFill repair_fill = RepairFill::tets;
  bool search = true;             ///< plan with the search portfolio (planner.h); false = plain greedy
  PlannerParams planner;          ///< budget, seed, side rule (its `order` is taken from `elimination`)
  TerminalParams terminal;        ///< filling the surface elimination got stuck on
  ReconstructionParams reconstruction;
  PillowParams pillow;            ///< forced configurations and pillowing, before placement
  /// With --pillow auto: when the optimized mesh's minimum scaled Jacobian is a forced corner's
  /// (all 4 points on the boundary, so no placement can raise it) and the boundary was not
  /// pillowed whole, the complex is pillowed again, counting as forced every corner up to the
  /// minimum plus this band, and placed and optimized again; the retry is kept when it leaves
  /// fewer hexes <= 0, or as many and raises the minimum by more than it lowers the mean
  /// (PillowRetryStats). 0 = no retry. It acts mostly on coarse smooth surfaces with no forced
  /// configuration.
  double pillow_retry_band = 0.1;
  /// Repair rounds (>= 0, 0 = none): while the untangled mesh keeps hexes with SJ <= 0, its
  /// complex is pillowed once more, locally around those hexes (each grown by PillowParams::grow
  /// rings and added while the set still pillows to a ball, fitted to the boundary like any
  /// shrink set), placed and untangled again; a round is kept when fewer hexes stay <= 0, and
  /// the rounds stop at the first that is not; then, when hexes still stay <= 0 and the first
  /// pillow was local, one more round pillows the whole boundary. The last resort: on the mesh kept after the
  /// other elimination orders were tried; not with --pillow none or --no-untangle.
  int repair_rounds = 3;
  /// When the plan's reconstruction refuses intrusions of concave steps (paper 5.4), rebuild
  /// the plan with covering steps after its concave runs (intrusion_cover.h); when all its
  /// intrusions go, mesh it too and keep the better mesh (better_result). Only with the search
  /// planner.
  bool intrusion_cover = true;
  /// When the plan meshed still has refused intrusions (no cover, or the cover refused some
  /// too), replay it with those steps eliminated towards their other side as convex steps
  /// (flip_refused_steps), again for the steps that plan refuses, up to this many rounds, and
  /// mesh it too when it refuses fewer; the better mesh is kept (better_result). 0 = off.
  int intrusion_flip_rounds = 3;
  PlacementParams placement;
  UntangleParams untangle;        ///< untangling and quality optimization, after placement
  QualityParams quality;
  /// When the untangled mesh keeps hexes with SJ <= 0, or elimination gets stuck (not for lack
  /// of time) or meets an invalid intrusion, other elimination orders are tried
  /// (alternative_orders: the other side rule, then the other method, then both), at most this
  /// many (>= 0; 0 = only the given order). The best result is kept (better_result); each try
  /// gets the planner's whole budget.
  int alternatives = 3;
  /// Try the alternatives even when the first mesh is valid and keep the best one (the largest
  /// minimum scaled Jacobian): slower, sometimes better.
  bool alternatives_always = false;
};

struct MeshTimings {
  double check_s = 0, elimination_s = 0, reconstruction_s = 0, placement_s = 0, quality_s = 0;
  double pillow_s = 0, untangle_s = 0;
  double other_orders_s = 0;  ///< the tries that were not kept (the given order's too when
                              ///< another was kept)
  double pillow_retry_s = 0;  ///< pillow, placement, untangling and quality of the embeddings
                              ///< not kept by the pillow retry and the repair pillow
  double intrusion_cover_s = 0;  ///< rebuilding the plan with covering steps, its
                                 ///< reconstruction, and the embedding of the plan not kept;
                                 ///< also the flipped plans (intrusion_flip_rounds)
};
/// The pillow retry (MeshParams::pillow_retry_band) or the repair pillow
/// (MeshParams::repair_rounds) of the order kept.
struct PillowRetryStats {
  bool tried = false;        ///< retry: the minimum was a forced corner's and the retry pillowed
                             ///< more; repair: hexes stayed <= 0
  bool kept = false;         ///< the retried (repaired) mesh is the one returned
  double forced_sj = 0.0;    ///< retry: its PillowParams::forced_sj
  double forced_min_sj = 0.0;  ///< retry: the forced corner bound that set it off
  int32_t seed_hexes = 0;    ///< repair: the hexes <= 0 given as seeds to the rounds kept
  int32_t new_hexes = 0;     ///< repair: hexes the pillows of the rounds kept added
  int32_t rounds = 0;        ///< repair: rounds embedded (a pillow that found no set is none)
  int32_t rounds_kept = 0;   ///< repair: rounds kept
  bool whole = false;        ///< repair: a last round pillowed the whole boundary (the local
                             ///< rounds left hexes <= 0 and the first pillow was local)
  bool whole_kept = false;   ///< ... and it was kept
  int32_t first_hexes = 0, retry_hexes = 0;  ///< hexes of the two meshes (repair: before the
                                             ///< rounds and of the mesh returned)
  double first_min_sj = 0.0, first_mean_sj = 0.0;  ///< quality of the first mesh
  double retry_min_sj = 0.0, retry_mean_sj = 0.0;  ///< ... and of the retried one
  int32_t first_nonpositive = 0, retry_nonpositive = 0;
  bool retry_ok = false;     ///< the retry embedded (its retry_* figures are set; else null
                             ///< in the JSON)
};

/// One elimination order the pipeline tried and what it gave.
struct OrderTry {
  Method method = Method::kremer;
  SideRule side_rule = SideRule::cost;
  StatusCode status = StatusCode::ok;
  int32_t hexes = 0;        ///< when status ok (null in the JSON otherwise, as the next two)
  int32_t nonpositive = 0;  ///< hexes with SJ <= 0, when status ok
  double min_sj = 0.0;      ///< when status ok
  double seconds = 0.0;     ///< elimination to quality
  /// The earlier try whose elimination plan this order reproduced: its mesh would be the same,
  /// so it was not built again (the outcome fields are copied from that try); -1 otherwise.
  int32_t same_plan_as = -1;
  /// A try made only because intrusions were refused whose plan predicted more than 1.5 times
  /// the hexes predicted by the plan of the mesh kept: not built (its predicted hex count; the
  /// status stays ok, the outcome fields are null in the JSON); 0 otherwise.
  int64_t skipped_plan_hexes = 0;
};

struct MeshResult {
  Status status;                 ///< first failure, or ok
  SurfaceDiagnosis diagnosis;    ///< input checks, chords, edges
  EliminationPlan plan;          ///< when the surface was valid
  PlannerStats planner;          ///< when the planner ran
  TerminalStats terminal;        ///< when elimination got stuck
  IntrusionCoverStats intrusion_cover;
  ReconstructionStats reconstruction;
  PillowStats pillow;
  std::vector<ForcedConfiguration> forced;  ///< found after reconstruction (before pillowing)
  PillowRetryStats pillow_retry;
  PillowRetryStats pillow_repair;
  PlacementStats placement;
  UntangleStats untangle;
  HexMesh mesh;                  ///< when status ok: boundary vertices first, in input order
  HexComplex complex;            ///< when status ok: the (pillowed) complex mesh was placed from,
                                 ///< hexes in the same order, its own vertex ids
  QualityReport quality;         ///< when status ok
  QuadSurface stuck_surface;     ///< when elimination got stuck: the surface it stopped at
  SurfaceRepairStats repair;     ///< MeshParams::repair_surface: what the repair changed
  QuadSurface repaired_surface;  ///< ... and the surface it made (the mesh's boundary)
  /// The repair's fill through tetrahedra (tet_fill.h, MeshParams::repair_fill): tetrahedra > 0
  /// when it was tried.
  TetFillStats tet_fill;
  bool tet_fill_kept = false;    ///< ... and its mesh is the one returned
  MeshTimings timings;
  OrderParams method;            ///< the elimination order (method and rules) this run used
  std::vector<OrderTry> tries;   ///< every order tried, the given one first (empty when the
                                 ///< input was rejected)
  int32_t kept_try = 0;          ///< the try this result is
};

/// The elimination orders tried after `base` when its mesh is not valid, in order: base with the
/// other side rule, base with the other method, base with both switched.
std::vector<OrderParams> alternative_orders(const OrderParams& base);

/// Whether a is better than b: a finished mesh before a failure, then fewer hexes with SJ <= 0,
/// then the larger minimum scaled Jacobian; false on a tie (the earlier try stays).
bool better_result(const MeshResult& a, const MeshResult& b);

MeshResult run_mesh(const PolygonSoup& soup, const MeshParams& params = {}, const Context& ctx = {});

/// The mesh's boundary faces (the input surface's quads, or the repaired surface's when the
/// repair was applied; mesh vertex ids) grouped into the patches sharp edges bound
/// (sharp_patches, edges sharper than `sharp_angle_deg`), for write_hex_mesh's boundary sets.
/// Empty (count 0) when r has no mesh.
BoundaryPatches boundary_patches(const MeshResult& r, double sharp_angle_deg);

/// The report: the quality JSON plus "status", "message", "input", "chords", "steps", "plan",
/// "reconstruction", "pillow", "pillow_retry", "pillow_repair", "placement", "untangle", "timings_s", "method" {name, side_rule,
/// rules}, "orders_tried" [{method, side_rule, status, hexes, nonpositive, min_sj, seconds,
/// same_plan_as, kept}].
nlohmann::json to_json(const MeshResult& result);

/// The budgets, passes and retries of `params` (what the CLI's --effort presets set), for the
/// report's "params" section.
nlohmann::json effort_to_json(const MeshParams& params);

}  // namespace hexpeel
