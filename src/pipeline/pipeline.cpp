// run_mesh: the stages in order, each timed; the first failure stops the run with its status.
//
// The output mesh numbers its vertices as the input surface does (vertex i of the output is
// input vertex i, at the same position), then the interior vertices in construction order.
#include "hexpeel/pipeline.h"

#include "pipeline/stages.h"

#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>

namespace hexpeel {
namespace pipeline_detail {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Renumbers the complex's vertices: input surface vertices first (by input id), then interior
/// vertices by creation order.
HexMesh renumber(const HexMesh& mesh, const HexComplex& complex, int32_t surface_points) {
  const int32_t nv = complex.num_vertices;
  std::vector<int32_t> to_new(nv, -1);
  int32_t next = surface_points;
  for (int32_t v = 0; v < nv; ++v)
    to_new[v] = complex.input_vertex[v] >= 0 ? complex.input_vertex[v] : next++;
  HexMesh out;
  out.points.resize(nv);
  for (int32_t v = 0; v < nv; ++v) out.points[to_new[v]] = mesh.points[v];
  out.hexes.reserve(mesh.hexes.size());
  for (const Hex& h : mesh.hexes) {
    Hex t;
    for (int k = 0; k < 8; ++k) t[k] = to_new[h[k]];
    out.hexes.push_back(t);
  }
  return out;
}

/// A plan's identity: its steps' chords, sides and kinds (the same plan gives the same mesh).
std::vector<int64_t> plan_key(const EliminationPlan& plan) {
  std::vector<int64_t> key;
  key.reserve(plan.steps.size());
  for (const PlanStep& s : plan.steps)
    key.push_back(static_cast<int64_t>(s.chord) * 4 + s.side * 2 + (s.concave ? 1 : 0));
  // A stuck fill depends on the order's rules too: the same steps with another fill are
  // another plan. -1 cannot be a step's key.
  if (!plan.terminal.empty()) {
    key.push_back(-1);
    key.push_back(plan.terminal.num_vertices);
    for (const Hex& h : plan.terminal.hexes) key.insert(key.end(), h.begin(), h.end());
  }
  return key;
}

/// Pillows `complex` as `pillow` says, places, untangles and optimizes it and checks the result:
/// r's pillow, forced, placement, untangle, mesh, quality and status, and their timings.
void embed_pillowed(const QuadSurface& surface, PillowResult pillowed, const MeshParams& params,
                    const Context& ctx, MeshResult& r, HexComplex* used);

void embed(const QuadSurface& surface, const HexComplex& complex, const MeshParams& params,
           const PillowParams& pillow, const Context& ctx, MeshResult& r, HexComplex* used) {
  const auto t = std::chrono::steady_clock::now();
  PillowResult pillowed = run_pillow(surface, complex, pillow, ctx);
  r.timings.pillow_s = seconds_since(t);
  embed_pillowed(surface, std::move(pillowed), params, ctx, r, used);
}

/// embed() after its pillow: r's pillow and forced from `pillowed`, then the rest.
void embed_pillowed(const QuadSurface& surface, PillowResult pillowed, const MeshParams& params,
                    const Context& ctx, MeshResult& r, HexComplex* used) {
  r.pillow = pillowed.stats;
  r.forced = std::move(pillowed.forced);
  if (!pillowed.status.ok()) {
    r.status = pillowed.status;
    return;
  }

  auto t = std::chrono::steady_clock::now();
  PlacementResult placed = run_placement(surface, pillowed.complex, params.placement, ctx);
  r.placement = placed.stats;
  r.timings.placement_s = seconds_since(t);
  if (!placed.status.ok()) {
    r.status = placed.status;
    return;
  }
  r.mesh = renumber(placed.mesh, pillowed.complex, surface.num_points());
  if (used) *used = std::move(pillowed.complex);

  if (params.untangle.untangle || params.untangle.optimize) {
    t = std::chrono::steady_clock::now();
    std::vector<uint8_t> fixed(r.mesh.points.size(), 0);
    std::fill(fixed.begin(), fixed.begin() + surface.num_points(), uint8_t{1});
    UntangleResult u = run_untangle(r.mesh, fixed, params.untangle, ctx);
    r.untangle = u.stats;
    r.timings.untangle_s = seconds_since(t);
    if (!u.status.ok()) {
      r.status = u.status;
      return;
    }
    r.mesh = std::move(u.mesh);
  }

  t = std::chrono::steady_clock::now();
  r.quality = run_quality(r.mesh, params.quality, &surface, ctx);
  r.timings.quality_s = seconds_since(t);
  if (!r.quality.is_ball || r.quality.boundary_matches_surface != true) {
    r.status = Status::error(StatusCode::internal_error,
                             "the constructed complex failed its final check: " +
                                 r.quality.topology_message + " " + r.quality.boundary_message);
  }
}

double embedding_seconds(const MeshTimings& t) {
  return t.pillow_s + t.placement_s + t.untangle_s + t.quality_s;
}

/// The hex count, min / mean SJ and hexes <= 0 of q as a retry's first (or retried) mesh.
void record_first(PillowRetryStats& s, const QualityReport& q) {
  s.first_hexes = q.hexes;
  s.first_min_sj = q.sj_min;
  s.first_mean_sj = q.sj_mean;
  s.first_nonpositive = q.sj_count_nonpositive;
}
void record_retry(PillowRetryStats& s, const QualityReport& q) {
  s.retry_hexes = q.hexes;
  s.retry_min_sj = q.sj_min;
  s.retry_mean_sj = q.sj_mean;
  s.retry_nonpositive = q.sj_count_nonpositive;
}

/// r takes `from`'s embedding: placement, untangling, mesh and quality with their timings, and
/// with `pillow` also its pillow stats (else from's pillow time adds to r's, whose pillow stats
/// describe the first pillow). The time of r's embedding given up goes to pillow_retry_s.
void adopt_embedding(MeshResult& r, MeshResult&& from, bool pillow) {
  MeshTimings& t = r.timings;
  t.pillow_retry_s += embedding_seconds(t) - (pillow ? 0.0 : t.pillow_s);
  if (pillow) {
    r.pillow = from.pillow;
    r.forced = std::move(from.forced);
    t.pillow_s = from.timings.pillow_s;
  } else {
    t.pillow_s += from.timings.pillow_s;
  }
  r.placement = from.placement;
  r.untangle = from.untangle;
  r.mesh = std::move(from.mesh);
  r.quality = std::move(from.quality);
  t.placement_s = from.timings.placement_s;
  t.untangle_s = from.timings.untangle_s;
  t.quality_s = from.timings.quality_s;
}

/// MeshParams::pillow_retry_band: when r's minimum is held by a forced corner, embeds `complex`
/// again with a pillow that also counts the corners up to the band above the minimum as forced,
/// and keeps what is better (fewer hexes <= 0; or as many and a minimum raised by more than the
/// mean falls). Not when the whole boundary was pillowed (the retry would pillow it again), when
/// the minimum is within the band of 1, and when no more corners count as forced.
void retry_pillow(const QuadSurface& surface, const HexComplex& complex, const MeshParams& params,
                  const Context& ctx, MeshResult& r) {
  if (params.pillow.mode != PillowMode::automatic || !(params.pillow_retry_band > 0.0) ||
      !params.untangle.untangle || !params.untangle.optimize || r.pillow.whole_boundary)
    return;
  // The untangler's forced corners and Verdict's minimum are the same determinants, computed
  // in another order: equal within rounding when the minimum is a forced corner's.
  if (!(r.untangle.forced_min_sj <= r.quality.sj_min + 1e-9)) return;
  // Within the band of a perfect hex (a voxel solid meshed by its cubes) there is nothing to win.
  if (r.quality.sj_min + params.pillow_retry_band >= 1.0) return;
  const auto t0 = std::chrono::steady_clock::now();
  PillowParams pillow = params.pillow;
  pillow.forced_sj = std::max(params.pillow.forced_sj, r.quality.sj_min + params.pillow_retry_band);
  if (find_forced_configurations(surface, complex, pillow.forced_sj).size() ==
      find_forced_configurations(surface, complex, params.pillow.forced_sj).size()) {
    r.timings.pillow_retry_s += seconds_since(t0);
    return;  // nothing more counts as forced: the same pillow
  }
  char msg[160];
  std::snprintf(msg, sizeof msg,
                "the minimum scaled Jacobian (%.4f) is a corner fixed by the boundary: pillowing "
                "again with corners up to %.4f counted as forced",
                r.quality.sj_min, pillow.forced_sj);
  ctx.info(msg);
  const double check_s = seconds_since(t0);  // the two scans above
  MeshResult retry;
  HexComplex retry_used;
  embed(surface, complex, params, pillow, ctx, retry, &retry_used);
  PillowRetryStats s;
  s.tried = true;
  s.forced_sj = pillow.forced_sj;
  s.forced_min_sj = r.untangle.forced_min_sj;
  record_first(s, r.quality);
  if (retry.status.ok()) {
    s.retry_ok = true;
    record_retry(s, retry.quality);
    const double gain = retry.quality.sj_min - r.quality.sj_min;
    const double loss = r.quality.sj_mean - retry.quality.sj_mean;
    s.kept = s.retry_nonpositive != s.first_nonpositive
                 ? s.retry_nonpositive < s.first_nonpositive
                 : gain > 0.0 && gain > loss;
  }
  r.timings.pillow_retry_s += check_s;
  if (s.kept) {
    adopt_embedding(r, std::move(retry), true);
    r.complex = std::move(retry_used);
  } else {
    r.timings.pillow_retry_s += embedding_seconds(retry.timings);
  }
  r.pillow_retry = s;
}

/// MeshParams::repair_rounds: while r keeps hexes with SJ <= 0 after untangling, pillows the
/// complex r was embedded from (r.complex, which follows the rounds kept) once more, locally around those hexes
/// (PillowParams::seed_hexes, seeds_only), embeds that from a new placement and keeps it when
/// fewer hexes stay <= 0; the rounds stop at the first that does not lower the count, or whose
/// pillow finds no shrink set. r's pillow stats stay the first pillow's; pillow_repair says
/// what the rounds did.
void repair_pillow(const QuadSurface& surface, const MeshParams& params, const Context& ctx,
                   MeshResult& r) {
  if (!r.status.ok() || params.repair_rounds <= 0 || params.pillow.mode == PillowMode::none ||
      !params.untangle.untangle || r.quality.sj_count_nonpositive == 0 || r.complex.hexes.empty())
    return;
  HexComplex& used = r.complex;
  PillowRetryStats& s = r.pillow_repair;
  s.tried = true;
  record_first(s, r.quality);
  // A silent pillow: a set that gives no ball ends the rounds, it is not a warning.
  Context quiet = ctx;
  quiet.log = nullptr;
  // One round: pillow the complex in hand with `pillow`, place and untangle again, keep the
  // result when fewer hexes stay <= 0. Returns whether it was kept (false also when the pillow
  // found no set).
  auto round = [&](const PillowParams& pillow, int64_t inverted, const char* where) {
    auto t = std::chrono::steady_clock::now();
    PillowResult pillowed = run_pillow(surface, used, pillow, quiet);
    const double pillow_s = seconds_since(t);
    if (!pillowed.status.ok() || pillowed.stats.new_hexes == 0) {
      r.timings.pillow_retry_s += pillow_s;
      return false;
    }
    ctx.info(std::to_string(inverted) + " hexes stay inverted: " +
             std::to_string(pillowed.stats.new_hexes) + " pillow hexes " + where +
             ", untangling again");
    HexComplex next;
    MeshResult repaired;
    repaired.timings.pillow_s = pillow_s;
    embed_pillowed(surface, std::move(pillowed), params, ctx, repaired, &next);
    ++s.rounds;
    if (!repaired.status.ok() ||
        repaired.quality.sj_count_nonpositive >= r.quality.sj_count_nonpositive) {
      r.timings.pillow_retry_s += embedding_seconds(repaired.timings);
      return false;
    }
    s.kept = true;
    ++s.rounds_kept;
    s.seed_hexes += repaired.pillow.seed_hexes;
    s.new_hexes += repaired.pillow.new_hexes;
    adopt_embedding(r, std::move(repaired), false);
    used = std::move(next);
    return true;
  };
  for (int n = 0; n < params.repair_rounds && r.quality.sj_count_nonpositive > 0; ++n) {
    PillowParams pillow = params.pillow;
    pillow.seeds_only = true;  // the first pillow's leftovers stay; the inverted hexes seed it
    const std::vector<double>& sj = r.quality.per_hex_sj;
    for (int32_t h = 0; h < static_cast<int32_t>(sj.size()); ++h)
      if (!(sj[h] > 0.0)) pillow.seed_hexes.push_back(h);
    // The worst first: their sets join S first when not all of them can.
    std::sort(pillow.seed_hexes.begin(), pillow.seed_hexes.end(), [&](int32_t a, int32_t b) {
      const double sa = std::isnan(sj[a]) ? -2.0 : sj[a], sb = std::isnan(sj[b]) ? -2.0 : sj[b];
      return sa != sb ? sa < sb : a < b;
    });
    if (!round(pillow, static_cast<int64_t>(pillow.seed_hexes.size()), "around them")) break;
  }
  // Local sets that do not help: a last round pillows the whole boundary of the complex in hand
  // (a smoothed block with a slot, no sharp edge: its local pillow and the repair's leave 8
  // hexes <= 0 in every order; the whole layer gives 0.37 / 0.80).
  if (r.quality.sj_count_nonpositive > 0 && !r.pillow.whole_boundary) {
    PillowParams pillow = params.pillow;
    pillow.mode = PillowMode::all;
    const int32_t rounds_before = s.rounds;
    s.whole_kept = round(pillow, r.quality.sj_count_nonpositive, "under the whole boundary");
    s.whole = s.rounds > rounds_before;
  }
  record_retry(s, r.quality);
  s.retry_ok = true;
}

/// ctx, with its warnings kept in `held` instead of passed on.
Context holding_warnings(const Context& ctx, std::vector<std::string>& held) {
  Context c = ctx;
  c.log = [&held, log = ctx.log](LogLevel level, std::string_view msg) {
    if (level == LogLevel::warning) held.emplace_back(msg);
    else if (log) log(level, msg);
  };
  return c;
}

/// A plan of r's surface other than r's (rebuilt by the intrusion cover, or flipped), and its
/// reconstruction `rec`, embedded (pillow retry included) as a result with r's method, planner,
/// fill and elimination time.
MeshResult embed_other_plan(const QuadSurface& surface, const MeshResult& r, EliminationPlan plan,
                            const ReconstructionResult& rec, const MeshParams& params,
                            const Context& ctx) {
  MeshResult o;
  o.method = r.method;
  o.plan = std::move(plan);
  o.planner = r.planner;
  o.terminal = r.terminal;
  o.reconstruction = rec.stats;
  o.timings.elimination_s = r.timings.elimination_s;
  o.timings.reconstruction_s = r.timings.reconstruction_s;
  embed(surface, rec.complex, params, params.pillow, ctx, o, &o.complex);
  if (o.status.ok()) retry_pillow(surface, rec.complex, params, ctx, o);
  return o;
}

/// Keeps the better of r and `other` in r (better_result; a tie keeps r), with its warnings in
/// `held` and r's intrusion cover stats, to which the embedding time of the one dropped goes.
/// Returns whether `other` was kept.
bool keep_better(MeshResult& r, MeshResult&& other, std::vector<std::string>& held,
                 std::vector<std::string>&& other_held) {
  IntrusionCoverStats& cs = r.intrusion_cover;
  const bool keep = better_result(other, r);
  const MeshResult& dropped = keep ? r : other;
  cs.time_s += embedding_seconds(dropped.timings) + dropped.timings.pillow_retry_s;
  if (keep) {
    other.intrusion_cover = cs;
    r = std::move(other);
    held = std::move(other_held);
  }
  return keep;
}

/// A flipped plan is not embedded when it predicts more than this many times the hexes of the
/// plan it flips (each flipped step extrudes its other side, often most of the surface: a
/// 1042-quad cut of pierrot's mesh, 2188 -> 4278 hexes for 3 steps).
constexpr double kMaxFlipGrowth = 3.0;

/// MeshParams::intrusion_flip_rounds: r's plan (meshed, with refused intrusions) replayed with
/// its refused steps eliminated towards their other side, again for what that plan refuses,
/// while a round refuses fewer; the last such plan is embedded and kept when better
/// (keep_better), with its warnings instead of `held`.
void flip_refused(const SurfaceDiagnosis& diagnosis, const MeshParams& params, const Context& ctx,
                  MeshResult& r, std::vector<std::string>& held) {
  const QuadSurface& surface = diagnosis.validation.surface;
  IntrusionCoverStats& cs = r.intrusion_cover;
  const auto t0 = std::chrono::steady_clock::now();
  cs.flip_tried = true;
  cs.flip_refused_before = static_cast<int32_t>(r.reconstruction.invalid_intrusion_steps.size());
  cs.flip_refused_after = cs.flip_refused_before;
  std::vector<std::string> held_flip;
  EliminationPlan plan;
  ReconstructionResult rec;
  const EliminationPlan* from = &r.plan;
  const std::vector<int32_t>* refused = &r.reconstruction.invalid_intrusion_steps;
  for (int round = 0; round < params.intrusion_flip_rounds && !refused->empty(); ++round) {
    EliminationState state(surface, diagnosis.chords, diagnosis.edges);
    int32_t flipped = 0;
    EliminationPlan next = flip_refused_steps(state, *from, *refused, flipped);
    if (!next.status.ok() || flipped == 0) break;
    std::vector<std::string> warnings;
    ReconstructionResult next_rec = run_reconstruction(
        surface, next, params.reconstruction, holding_warnings(ctx, warnings), &state);
    if (!next_rec.status.ok() || next_rec.stats.invalid_intrusion_steps.size() >= refused->size())
      break;
    ++cs.flip_rounds;
    cs.flipped_steps += flipped;
    plan = std::move(next);
    rec = std::move(next_rec);
    held_flip = std::move(warnings);
    from = &plan;
    refused = &rec.stats.invalid_intrusion_steps;
    cs.flip_refused_after = static_cast<int32_t>(refused->size());
  }
  cs.time_s += seconds_since(t0);
  if (cs.flip_rounds == 0) return;
  if (static_cast<double>(plan.stats.predicted_hexes) >
      kMaxFlipGrowth * static_cast<double>(r.plan.stats.predicted_hexes)) {
    ctx.info("the plan with refused concave steps turned to their other side predicts " +
             std::to_string(plan.stats.predicted_hexes) + " hexes, over " +
             std::to_string(static_cast<int>(kMaxFlipGrowth)) + " times the " +
             std::to_string(r.plan.stats.predicted_hexes) + " planned: not built");
    return;
  }
  ctx.info(std::to_string(cs.flip_refused_before) + " intrusions refused: meshing the plan with " +
           std::to_string(cs.flipped_steps) + " of its concave steps turned to their other side");
  MeshResult flipped = embed_other_plan(surface, r, std::move(plan), rec, params,
                                        holding_warnings(ctx, held_flip));
  cs.flip_kept = keep_better(r, std::move(flipped), held, std::move(held_flip));
}

/// Least planning budget of the intrusion cover's replans (budget seconds).
constexpr double kMinCoverBudget = 3.0;

/// The stages after the input checks, with elimination order `order`; fills everything but
/// `diagnosis`, `tries` and the check time. `plans` holds the keys of the plans meshed before;
/// when this order plans one of them again, it stops after planning and `same_as` names it.
/// This order's plan key is appended to `plans` ({-1} when planning failed). When
/// max_plan_hexes > 0 and the plan predicts more hexes, it also stops after planning and sets
/// `too_large`.
MeshResult mesh_with_order(const SurfaceDiagnosis& diagnosis, const MeshParams& params,
                           const OrderParams& order, const Context& ctx,
                           std::vector<std::vector<int64_t>>& plans, int32_t& same_as,
                           int64_t max_plan_hexes, bool& too_large) {
  same_as = -1;
  too_large = false;
  MeshResult r;
  r.method = order;
  const QuadSurface& surface = diagnosis.validation.surface;

  auto t = std::chrono::steady_clock::now();
  EliminationState state(surface, diagnosis.chords, diagnosis.edges);
  if (params.search) {
    PlannerParams pp = params.planner;
    pp.order = order;
    PlannerResult pr = run_planner(state, pp, ctx);
    r.plan = std::move(pr.plan);
    r.planner = pr.stats;
  } else {
    EliminationParams ep = params.elimination;
    ep.order = order;
    r.plan = run_elimination(state, ep, ctx);
  }
  if (r.plan.status.code == StatusCode::stuck && !r.plan.stats.timed_out) {
    // A hex complex for the surface it stopped at (terminal.h) completes the plan; not when
    // greedy elimination was stopped by --time-limit (that surface is not stuck, and the user
    // asked to give up).
    TerminalParams tp = params.terminal;
    tp.sharp_angle_deg = params.sharp_angle_deg;
    PlannerParams pp = params.planner;
    pp.order = order;
    r.terminal = fill_stuck_surface(state, r.plan, tp, pp, ctx);
    if (r.terminal.filled)
      ctx.warn("elimination got stuck on a surface of " + std::to_string(r.terminal.stuck_quads) +
               " quads; it was filled by a pit of " + std::to_string(r.terminal.pits) +
               " layer(s) (" + std::to_string(r.terminal.hexes) + " hexes)");
  }
  r.timings.elimination_s = seconds_since(t);
  if (!r.plan.status.ok()) {
    plans.push_back({-1});  // no plan: matches no key
    r.status = r.plan.status;
    if (r.plan.status.code == StatusCode::stuck) r.stuck_surface = state.current_surface();
    return r;
  }
  std::vector<int64_t> key = plan_key(r.plan);
  for (size_t i = 0; i < plans.size() && same_as < 0; ++i)
    if (plans[i] == key) same_as = static_cast<int32_t>(i);
  plans.push_back(std::move(key));
  if (same_as >= 0) return r;
  too_large = max_plan_hexes > 0 && r.plan.stats.predicted_hexes > max_plan_hexes;
  if (too_large) return r;

  t = std::chrono::steady_clock::now();
  // With the cover to try, warnings wait until it is known which plan is meshed.
  const bool may_cover = params.intrusion_cover && params.search && r.plan.stats.concave_steps > 0 &&
                         r.plan.terminal.empty();
  // ... and so may the flip of refused steps (flip_refused).
  const bool may_flip = params.intrusion_flip_rounds > 0 && r.plan.stats.concave_steps > 0;
  std::vector<std::string> held;
  const Context quiet = may_cover || may_flip ? holding_warnings(ctx, held) : ctx;
  ReconstructionResult rec = run_reconstruction(surface, r.plan, params.reconstruction, quiet, &state);
  r.reconstruction = rec.stats;
  r.timings.reconstruction_s = seconds_since(t);
  // Intrusions refused: the plan rebuilt with covering steps after its concave runs
  // (intrusion_cover.h), when all its intrusions go, is meshed too, and the better mesh kept
  // (better_result). Both are meshed because intruding is not always better: random voxel
  // solids whose refused steps were extruded into their ideal cubes got 0.07-0.53 covered.
  MeshResult covered;
  bool cover = false;
  std::vector<std::string> held_cover;
  if (may_cover && rec.status.code != StatusCode::internal_error &&
      !rec.stats.invalid_intrusion_steps.empty()) {
    IntrusionCoverStats& cs = r.intrusion_cover;
    cs.refused_before = static_cast<int32_t>(rec.stats.invalid_intrusion_steps.size());
    cs.refused_after = -1;
    PlannerParams pp = params.planner;
    pp.order = order;
    // The replans are a second try at a plan already found: they get what the first search
    // used, twice over and at least kMinCoverBudget, not the whole budget again (a 1042-quad
    // cut of pierrot's mesh planned in 2 budget seconds, then its replans searched the whole
    // 30 without a plan, 43 s, in each of the four orders; screw2's replan takes 0.4).
    pp.budget_s = std::min(pp.budget_s, std::max(kMinCoverBudget, 2.0 * r.planner.effort_s));
    EliminationState cover_state(surface, diagnosis.chords, diagnosis.edges);
    EliminationPlan cp = cover_concave_steps(cover_state, r.plan, pp, quiet, cs);
    if (cp.status.ok()) {
      const Context quiet_cover = holding_warnings(ctx, held_cover);
      const auto tc = std::chrono::steady_clock::now();
      ReconstructionResult rec2 = run_reconstruction(surface, cp, params.reconstruction, quiet_cover, &cover_state);
      cs.time_s += seconds_since(tc);
      if (rec2.status.code != StatusCode::internal_error)
        cs.refused_after = static_cast<int32_t>(rec2.stats.invalid_intrusion_steps.size());
      if (rec2.status.ok() && cs.refused_after == 0) {
        cover = true;
        covered = embed_other_plan(surface, r, std::move(cp), rec2, params, quiet_cover);
      }
    }
  }
  if (rec.status.ok()) {
    embed(surface, rec.complex, params, params.pillow, quiet, r, &r.complex);
    if (r.status.ok()) retry_pillow(surface, rec.complex, params, quiet, r);
  } else {
    r.status = rec.status;
  }
  if (cover)
    r.intrusion_cover.kept = keep_better(r, std::move(covered), held, std::move(held_cover));
  if (params.intrusion_flip_rounds > 0 && r.status.ok() &&
      !r.reconstruction.invalid_intrusion_steps.empty())
    flip_refused(diagnosis, params, ctx, r, held);
  r.timings.intrusion_cover_s = r.intrusion_cover.time_s;
  for (const std::string& w : held) ctx.warn(w);
  return r;
}

/// Whether r's order ran out of its time (the planner's budget, greedy's time limit): that ends
/// the tries, the limit is the user's.
bool ran_out_of_time(const MeshResult& r, const MeshParams& params) {
  return params.search ? r.planner.budget_exhausted : r.plan.stats.timed_out;
}

/// Whether another elimination order may do better than r: its untangled mesh keeps hexes with
/// SJ <= 0, or the order itself failed (stuck, or an intrusion that --strict-intrusion refuses)
/// without running out of time. A placement that was not untangled is expected to keep inverted
/// hexes.
bool order_may_help(const MeshResult& r, const MeshParams& params) {
  // A plan completed by the stuck fill after the budget ran out: the others would run out too.
  if (r.status.ok() && r.terminal.filled && ran_out_of_time(r, params)) return false;
  if (r.status.ok()) return params.untangle.untangle && r.quality.sj_count_nonpositive > 0;
  return !ran_out_of_time(r, params) &&
         (r.status.code == StatusCode::stuck || r.status.code == StatusCode::invalid_intrusion);
}

/// Whether r's reconstruction extruded concave steps whose intrusion it refused: their layers go
/// outward where the method meant them inward, and must fold into the concave region (screw2's
/// worst hexes, 0.031, are there). The other side rule plans the surface differently, which may
/// intrude those steps or place their layers better (on screw2 it refuses the same five steps
/// but ends at 0.057 / 0.622 instead of 0.031 / 0.606); the original method, with no concave
/// steps, folds such layers more (on screw2 it keeps hexes <= 0), so only the Kremer alternative
/// is tried for this. Not when the order ran out of its time, as above.
bool refused_intrusions(const MeshResult& r, const MeshParams& params) {
  return r.status.ok() && !r.reconstruction.invalid_intrusion_steps.empty() &&
         !ran_out_of_time(r, params);
}

double total_seconds(const MeshTimings& t) {
  return t.elimination_s + t.reconstruction_s + t.pillow_s + t.placement_s + t.untangle_s +
         t.quality_s + t.pillow_retry_s + t.intrusion_cover_s;
}

/// A try made only for refused intrusions builds no plan of more than this many times the
/// kept mesh's planned hexes (the messages say 1.5).
constexpr double kMaxPlanGrowth = 1.5;

OrderTry summarize(const MeshResult& r, double seconds) {
  OrderTry t;
  t.method = r.method.method;
  t.side_rule = r.method.side_rule;
  t.status = r.status.code;
  if (r.status.ok()) {
    t.hexes = r.quality.hexes;
    t.nonpositive = r.quality.sj_count_nonpositive;
    t.min_sj = r.quality.sj_min;
  }
  t.seconds = seconds;
  return t;
}

std::string describe(const OrderParams& o) {
  return "method " + std::string(to_string(o.method)) + ", side rule " +
         std::string(to_string(o.side_rule));
}

}  // namespace pipeline_detail

using namespace pipeline_detail;

std::vector<OrderParams> alternative_orders(const OrderParams& base) {
  auto other_rule = [](SideRule s) {
    return s == SideRule::cost ? SideRule::heavier : SideRule::cost;
  };
  auto other_method = [](Method m) {
    return m == Method::kremer ? Method::original : Method::kremer;
  };
  std::vector<OrderParams> out(3, base);
  out[0].side_rule = other_rule(base.side_rule);
  out[1].method = other_method(base.method);
  out[2].side_rule = other_rule(base.side_rule);
  out[2].method = other_method(base.method);
  return out;
}

bool better_result(const MeshResult& a, const MeshResult& b) {
  if (a.status.ok() != b.status.ok()) return a.status.ok();
  if (!a.status.ok()) return false;
  if (a.quality.sj_count_nonpositive != b.quality.sj_count_nonpositive)
    return a.quality.sj_count_nonpositive < b.quality.sj_count_nonpositive;
  return a.quality.sj_min > b.quality.sj_min;
}

BoundaryPatches boundary_patches(const MeshResult& r, double sharp_angle_deg) {
  BoundaryPatches out;
  if (!r.status.ok()) return out;
  const QuadSurface& s = r.repair.applied ? r.repaired_surface : r.diagnosis.validation.surface;
  const QuadAdjacency adj = build_adjacency(s);
  out.patch = sharp_patches(s, adj, classify_edges(s, adj, sharp_angle_deg), out.count);
  out.faces = s.quads;
  return out;
}

MeshResult run_mesh(const PolygonSoup& soup, const MeshParams& params, const Context& ctx) {
  // Far from unit size, the whole run works on the soup scaled by a power of two (exact), and
  // what it returns is scaled back: the boundary vertices come back exactly as read.
  if (const int k = scale_exponent(soup.points); k != 0) {
    PolygonSoup scaled = soup;
    scale_points(scaled.points, k);
    MeshResult r = run_mesh(scaled, params, ctx);
    scale_points(r.mesh.points, -k);
    scale_points(r.diagnosis.validation.surface.points, -k);
    scale_points(r.stuck_surface.points, -k);
    scale_points(r.repaired_surface.points, -k);
    for (WorstHex& w : r.quality.worst) w.centroid = std::ldexp(1.0, -k) * w.centroid;
    return r;
  }
  auto t = std::chrono::steady_clock::now();
  ValidationParams validation = params.validation;
  validation.allow_odd = validation.allow_odd || params.repair_surface;
  SurfaceDiagnosis diagnosis = diagnose_surface(soup, params.sharp_angle_deg, ctx, validation);
  const double check_s = seconds_since(t);
  if (params.repair_surface && diagnosis.validation.status.ok() &&
      (diagnosis.status.code == StatusCode::self_intersecting_chord ||
       diagnosis.validation.surface.num_quads() % 2 != 0))
    return mesh_repaired(diagnosis, params, ctx, check_s);
  if (!diagnosis.status.ok()) {
    MeshResult r;
    r.method = params.elimination.order;
    r.status = diagnosis.status;
    r.diagnosis = std::move(diagnosis);
    r.timings.check_s = check_s;
    return r;
  }

  t = std::chrono::steady_clock::now();
  std::vector<std::vector<int64_t>> plans;
  int32_t same_as = -1;
  bool too_large = false;
  MeshResult best = mesh_with_order(diagnosis, params, params.elimination.order, ctx, plans,
                                    same_as, 0, too_large);
  std::vector<OrderTry> tries{summarize(best, seconds_since(t))};
  double others_s = 0.0;
  const std::vector<OrderParams> alternatives = alternative_orders(params.elimination.order);
  for (int i = 0; i < params.alternatives && i < static_cast<int>(alternatives.size()); ++i) {
    const bool invalid = order_may_help(best, params);
    const bool refused = alternatives[i].method == Method::kremer && refused_intrusions(best, params);
    if (!params.alternatives_always && !invalid && !refused) break;
    const char* why = invalid ? (best.status.ok() ? "the mesh keeps hexes with scaled Jacobian <= 0"
                                                  : "elimination failed")
                      : refused ? "concave steps were extruded (their intrusion refused)"
                                : "looking for a better mesh";
    ctx.info(std::string(why) + ": trying elimination order " + describe(alternatives[i]));
    t = std::chrono::steady_clock::now();
    // A try made only because intrusions were refused is looking for a better placement of
    // the same shape: a plan of far more hexes than the mesh in hand is not built (a swivel cut:
    // 43029 hexes against 16679, 25 min on a loaded machine, inverted in the end).
    const int64_t max_plan_hexes =
        !invalid && !params.alternatives_always && best.status.ok()
            ? static_cast<int64_t>(kMaxPlanGrowth * static_cast<double>(best.plan.stats.predicted_hexes))
            : 0;
    MeshResult r = mesh_with_order(diagnosis, params, alternatives[i], ctx, plans, same_as,
                                   max_plan_hexes, too_large);
    if (too_large) {
      OrderTry skipped = summarize(r, seconds_since(t));
      skipped.skipped_plan_hexes = r.plan.stats.predicted_hexes;
      tries.push_back(skipped);
      others_s += r.timings.elimination_s;
      ctx.info("its plan predicts " + std::to_string(r.plan.stats.predicted_hexes) +
               " hexes, over 1.5 times the " + std::to_string(best.plan.stats.predicted_hexes) +
               " planned for the mesh kept: not built");
      continue;
    }
    if (same_as >= 0) {  // the same mesh again: not built twice
      OrderTry same = tries[same_as];
      same.method = alternatives[i].method;
      same.side_rule = alternatives[i].side_rule;
      same.seconds = seconds_since(t);
      same.same_plan_as = same_as;
      tries.push_back(same);
      others_s += r.timings.elimination_s;
      continue;
    }
    tries.push_back(summarize(r, seconds_since(t)));
    if (better_result(r, best)) {
      others_s += total_seconds(best.timings);
      best = std::move(r);
      best.kept_try = static_cast<int32_t>(tries.size()) - 1;
    } else {
      others_s += total_seconds(r.timings);
    }
  }
  // The repair pillow is the last resort, after the other orders: on an inverted mesh each of
  // its rounds is a long untangling (screw2 with the original method: 141 -> 8 hexes <= 0 in
  // 3 rounds, 12 min), where another order is often valid at once.
  repair_pillow(diagnosis.validation.surface, params, ctx, best);
  if (best.pillow_repair.kept) {  // the kept try's figures are those of the mesh returned
    OrderTry& kept = tries[best.kept_try];
    kept.hexes = best.quality.hexes;
    kept.nonpositive = best.quality.sj_count_nonpositive;
    kept.min_sj = best.quality.sj_min;
  }
  best.tries = std::move(tries);
  best.diagnosis = std::move(diagnosis);
  best.timings.check_s = check_s;
  best.timings.other_orders_s = others_s;
  return best;
}

}  // namespace hexpeel
