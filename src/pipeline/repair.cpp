// The surface repair's ways to a mesh (MeshParams::repair_surface, repair_fill): the refined
// surface by dual cycle elimination, the surface split into six through tetrahedra.
#include "hexpeel/pipeline.h"

#include "pipeline/stages.h"

#include <chrono>
#include <string>

namespace hexpeel::pipeline_detail {

namespace {

/// The repair's ways to mesh (MeshParams::repair_fill), each a small unit; `inner` are the
/// params a refined surface is meshed with (no repair, no odd count).

/// A result that says the refinement itself failed.
MeshResult repair_failed(const SurfaceDiagnosis& diagnosis, const MeshParams& params,
                         SurfaceRepair&& rep, double check_s) {
  MeshResult r;
  r.method = params.elimination.order;
  r.status = rep.status;
  r.diagnosis = diagnosis;
  r.repair = rep.stats;
  r.timings.check_s = check_s;
  return r;
}

/// The surface refined (split into six where chords cross themselves, grown until every chord
/// is simple, into four elsewhere; or into six everywhere) and meshed by dual cycle elimination.
MeshResult eliminate_refined(const SurfaceDiagnosis& diagnosis, const MeshParams& params,
                             const MeshParams& inner, bool everywhere, const Context& ctx,
                             double check_s) {
  const auto t = std::chrono::steady_clock::now();
  SurfaceRepair rep = repair_surface(diagnosis.validation.surface, everywhere);
  const double repair_s = seconds_since(t);
  if (!rep.status.ok()) return repair_failed(diagnosis, params, std::move(rep), check_s + repair_s);
  const SurfaceRepairStats& st = rep.stats;
  if (everywhere)
    ctx.info("the repaired surface did not mesh with every hex positive: trying it split into "
             "six everywhere");
  ctx.warn("surface repaired (--repair-surface): " + std::to_string(st.input_quads) + " quads" +
           (st.input_odd ? " (odd)" : "") + " with " + std::to_string(st.input_self_crossings) +
           " self-crossing" + (st.input_self_crossings == 1 ? "" : "s") + " -> " +
           std::to_string(st.output_quads) + " quads (" + std::to_string(st.six_split.size()) +
           " split into six, the rest into four), every chord simple; the mesh's boundary is "
           "the repaired surface, not the input");
  MeshResult r = run_mesh(to_polygon_soup(rep.surface), inner, ctx);
  r.timings.check_s += check_s + repair_s;  // the input's check and the repair
  r.repair = rep.stats;
  r.repaired_surface = std::move(rep.surface);
  return r;
}

/// The surface split into six everywhere, filled through tetrahedra (tet_fill.h), then pillowed,
/// placed and optimized like any complex.
MeshResult fill_through_tets(const SurfaceDiagnosis& diagnosis, const MeshParams& params,
                             const MeshParams& inner, const Context& ctx, double check_s) {
  const auto t = std::chrono::steady_clock::now();
  SurfaceRepair rep = repair_surface(diagnosis.validation.surface, true);
  if (!rep.status.ok()) return repair_failed(diagnosis, params, std::move(rep), check_s + seconds_since(t));
  ctx.info("filling the surface split into six through tetrahedra");
  TetFill tf = tet_fill(diagnosis.validation.surface, rep.surface);
  MeshResult r;
  r.method = params.elimination.order;
  r.repair = rep.stats;
  r.tet_fill = tf.stats;
  r.status = tf.status;
  r.diagnosis = diagnose_surface(to_polygon_soup(rep.surface), params.sharp_angle_deg, {},
                                 inner.validation);
  r.timings.check_s = check_s + seconds_since(t);
  if (tf.status.ok()) {
    r.reconstruction.hexes = static_cast<int32_t>(tf.complex.hexes.size());
    embed(rep.surface, tf.complex, inner, inner.pillow, ctx, r, &r.complex);
  } else {
    ctx.warn("the repair's tetrahedral fallback failed: " + tf.status.message);
  }
  r.repaired_surface = std::move(rep.surface);
  return r;
}

bool valid_mesh(const MeshResult& r) { return r.status.ok() && r.quality.sj_count_nonpositive == 0; }

}  // namespace

MeshResult mesh_repaired(const SurfaceDiagnosis& diagnosis, const MeshParams& params,
                                const Context& ctx, double check_s) {
  MeshParams inner = params;
  inner.repair_surface = false;
  inner.validation.allow_odd = false;
  const bool eliminate = params.repair_fill != MeshParams::RepairFill::tets;
  const bool tets = params.repair_fill != MeshParams::RepairFill::elimination;
  MeshResult best;
  bool have = false;
  double others_s = 0.0;  // the results not kept
  auto consider = [&](MeshResult&& r) {
    const bool keep = !have || better_result(r, best);
    others_s += total_seconds(keep ? best.timings : r.timings);
    if (keep) best = std::move(r);
    have = true;
    return keep;
  };
  if (eliminate) {
    consider(eliminate_refined(diagnosis, params, inner, false, ctx, check_s));
    if (!valid_mesh(best) && best.repair.six_split.size() != static_cast<size_t>(best.repair.input_quads))
      consider(eliminate_refined(diagnosis, params, inner, true, ctx, check_s));
  }
  if (tets && (tet_fill_available() || !eliminate)) {
    MeshResult r = fill_through_tets(diagnosis, params, inner, ctx, check_s);
    const TetFillStats stats = r.tet_fill;
    r.tet_fill_kept = r.status.ok();
    if (consider(std::move(r))) {
      if (best.status.ok())
        ctx.warn("surface repaired (--repair-surface): " + std::to_string(best.repair.input_quads) +
                 " quads -> " + std::to_string(best.repair.output_quads) + " quads (every quad "
                 "split into six), filled through " + std::to_string(best.tet_fill.tetrahedra) +
                 " tetrahedra (4 hexes each); the mesh's boundary is the repaired surface, not the input");
    } else {
      best.tet_fill = stats;
    }
  }
  best.timings.other_orders_s += others_s;
  return best;
}

}  // namespace hexpeel::pipeline_detail
