// The whole meshing job on a surface already read: check, chords, elimination, reconstruction,
// placement, quality. The CLI is a thin shell around run_mesh (reading and writing files is its
// job, so it can time them and pick file names).
#pragma once

#include "hexpeel/diagnosis.h"
#include "hexpeel/elimination.h"
#include "hexpeel/planner.h"
#include "hexpeel/embedding.h"
#include "hexpeel/pillow.h"
#include "hexpeel/quality.h"
#include "hexpeel/reconstruction.h"
#include "hexpeel/untangle.h"

#include <nlohmann/json.hpp>

namespace hexpeel {

struct MeshParams {
  double sharp_angle_deg = 60.0;  ///< deviation from flat (degrees, in (0, 180)) that makes an edge sharp
  ValidationParams validation;
  EliminationParams elimination;  ///< its `order` rules serve the planner too
  bool search = true;             ///< plan with the search portfolio (planner.h); false = plain greedy
  PlannerParams planner;          ///< budget, seed, side rule (its `order` is taken from `elimination`)
  ReconstructionParams reconstruction;
  PillowParams pillow;            ///< forced configurations and pillowing, before placement
  PlacementParams placement;
  UntangleParams untangle;        ///< untangling and quality optimization, after placement
  QualityParams quality;
};

struct MeshTimings {
  double check_s = 0, elimination_s = 0, reconstruction_s = 0, placement_s = 0, quality_s = 0;
  double pillow_s = 0, untangle_s = 0;
};

struct MeshResult {
  Status status;                 ///< first failure, or ok
  SurfaceDiagnosis diagnosis;    ///< input checks, chords, edges
  EliminationPlan plan;          ///< when the surface was valid
  PlannerStats planner;          ///< when the planner ran
  ReconstructionStats reconstruction;
  PillowStats pillow;
  std::vector<ForcedConfiguration> forced;  ///< found after reconstruction (before pillowing)
  PlacementStats placement;
  UntangleStats untangle;
  HexMesh mesh;                  ///< when status ok: boundary vertices first, in input order
  QualityReport quality;         ///< when status ok
  QuadSurface stuck_surface;     ///< when elimination got stuck: the surface it stopped at
  MeshTimings timings;
  OrderParams method;            ///< the elimination order (method and rules) this run used
};

MeshResult run_mesh(const PolygonSoup& soup, const MeshParams& params = {}, const Context& ctx = {});

/// The report: the quality JSON plus "status", "message", "input", "chords", "steps", "plan",
/// "reconstruction", "pillow", "placement", "untangle", "timings_s", "method" {name, rules}.
nlohmann::json to_json(const MeshResult& result);

}  // namespace hexpeel
