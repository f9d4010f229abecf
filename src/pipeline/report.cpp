// The mesh report: MeshResult and the run's budgets as JSON (pipeline.h).
#include "hexpeel/pipeline.h"

#include <string>

namespace hexpeel {

namespace {
bool params_used_search(const MeshResult& r) { return r.planner.nodes > 0 || r.planner.plans_tried > 0; }
}  // namespace

nlohmann::json to_json(const MeshResult& r) {
  nlohmann::json j = r.status.ok() ? to_json(r.quality) : nlohmann::json::object();
  j["status"] = std::string(to_string(r.status.code));
  j["message"] = r.status.message;
  j["input"] = to_json(r.diagnosis);
  if (r.repair.input_quads > 0) {  // the repair was tried
    j["repair"] = to_json(r.repair);
    if (r.tet_fill.tetrahedra > 0)
      j["repair"]["tet_fill"] = {{"tetrahedra", r.tet_fill.tetrahedra},
                                 {"interior_nodes", r.tet_fill.interior_nodes},
                                 {"time_s", r.tet_fill.time_s},
                                 {"kept", r.tet_fill_kept}};
  }
  const ChordStats& cs = r.diagnosis.chord_stats;
  j["chords"] = {{"count", cs.count},
                 {"min_length", cs.min_length},
                 {"mean_length", cs.mean_length},
                 {"max_length", cs.max_length},
                 {"self_intersecting", cs.self_intersecting}};
  const OrderParams& order = r.method;
  j["method"] = {{"name", std::string(to_string(order.method))},
                 {"side_rule", std::string(to_string(order.side_rule))},
                 {"rules",
                  order.method == Method::kremer
                      ? nlohmann::json{{"zero_volume", order.zero_volume},
                                       {"zero_volume_tolerance_deg", order.zero_volume_tolerance_deg},
                                       {"enclosed", order.enclosed},
                                       {"concave", order.concave},
                                       {"concave_min", order.concave_min},
                                       {"both_convex_min", order.both_convex_min},
                                       {"false_positive", order.false_positive},
                                       {"concave_waits_for_enclosed", order.concave_waits_for_enclosed}}
                      : nlohmann::json::object()}};
  j["orders_tried"] = nlohmann::json::array();
  for (size_t i = 0; i < r.tries.size(); ++i) {
    const OrderTry& t = r.tries[i];
    // A failed try, or one not built, has no mesh to describe.
    const bool ok = t.status == StatusCode::ok && t.skipped_plan_hexes == 0;
    j["orders_tried"].push_back({{"method", std::string(to_string(t.method))},
                                 {"side_rule", std::string(to_string(t.side_rule))},
                                 {"status", std::string(to_string(t.status))},
                                 {"hexes", ok ? nlohmann::json(t.hexes) : nlohmann::json()},
                                 {"nonpositive", ok ? nlohmann::json(t.nonpositive) : nlohmann::json()},
                                 {"min_sj", ok ? nlohmann::json(t.min_sj) : nlohmann::json()},
                                 {"seconds", t.seconds},
                                 {"same_plan_as", t.same_plan_as},
                                 {"skipped_plan_hexes", t.skipped_plan_hexes},
                                 {"kept", static_cast<int32_t>(i) == r.kept_try}});
  }
  j["steps"] = r.plan.stats.steps;
  j["plan"] = {{"steps", r.plan.stats.steps},
               {"flat_steps", r.plan.stats.flat_steps},
               {"concave_steps", r.plan.stats.concave_steps},
               {"predicted_hexes", r.plan.stats.predicted_hexes},
               {"feasibility_tests", r.plan.stats.feasibility_tests}};
  if (r.plan.status.code == StatusCode::stuck) {
    nlohmann::json reasons = nlohmann::json::object();
    for (size_t i = 0; i < r.plan.stuck.reasons.size(); ++i)
      if (r.plan.stuck.reasons[i] > 0)
        reasons[std::string(to_string(static_cast<Infeasible>(i)))] = r.plan.stuck.reasons[i];
    j["stuck"] = {{"quads_left", r.plan.stuck.quads_left},
                  {"chords_left", r.plan.stuck.chords_left},
                  {"reasons", reasons}};
  }
  if (r.terminal.tried)
    j["stuck_fill"] = {{"filled", r.terminal.filled},
                       {"stuck_quads", r.terminal.stuck_quads},
                       {"tries", r.terminal.tries},
                       {"effort_s", r.terminal.effort_s},
                       {"pits", r.terminal.pits},
                       {"pit_quads", r.terminal.pit_quads},
                       {"hexes", r.terminal.hexes},
                       {"time_s", r.terminal.time_s}};
  if (params_used_search(r)) {
    j["planner"] = {{"plans_tried", r.planner.plans_tried},
                    {"nodes", r.planner.nodes},
                    {"backtracks", r.planner.backtracks},
                    {"states_remembered", r.planner.states_remembered},
                    {"stuck_events", r.planner.stuck_events},
                    {"conflict_rounds", r.planner.conflict_rounds},
                    {"best_cost", r.planner.best_cost},
                    {"strategy", r.planner.strategy},
                    {"budget_exhausted", r.planner.budget_exhausted},
                    {"time_s", r.planner.time_s},
                    {"first_plan_s", r.planner.first_plan_s}};
  }
  if (r.intrusion_cover.tried || r.intrusion_cover.flip_tried) {
    const IntrusionCoverStats& c = r.intrusion_cover;
    j["intrusion_cover"] = {{"tried", c.tried},
                            {"kept", c.kept},
                            {"cover_steps", c.cover_steps},
                            {"replans", c.replans},
                            {"uncovered_quads", c.uncovered_quads},
                            {"refused_before", c.refused_before},
                            {"refused_after", c.refused_after < 0 ? nlohmann::json(nullptr)
                                                                  : nlohmann::json(c.refused_after)},
                            {"predicted_hexes", c.predicted_hexes},
                            {"replan_effort_s", c.replan_effort_s},
                            {"time_s", c.time_s},
                            {"flip", {{"tried", c.flip_tried},
                                      {"kept", c.flip_kept},
                                      {"rounds", c.flip_rounds},
                                      {"flipped_steps", c.flipped_steps},
                                      {"refused_before", c.flip_refused_before},
                                      {"refused_after", c.flip_refused_after}}}};
  }
  j["reconstruction"] = {{"hexes", r.reconstruction.hexes},
                         {"slit_edges", r.reconstruction.slit_edges},
                         {"steps_verified", r.reconstruction.steps_verified},
                         {"intrusions", r.reconstruction.intrusions},
                         {"hexes_intruded", r.reconstruction.hexes_intruded},
                         {"invalid_intrusion_steps", r.reconstruction.invalid_intrusion_steps}};
  j["placement"] = {{"method", "harmonic"},
                    {"interior_vertices", r.placement.interior_vertices},
                    {"coincident_pairs_separated", r.placement.coincident_pairs - r.placement.coincident_after},
                    {"coincident_pairs_left", r.placement.coincident_after},
                    {"nonpositive_hexes", r.placement.nonpositive_hexes}};
  {
    const PillowStats& p = r.pillow;
    nlohmann::json forced = nlohmann::json::array();
    for (size_t i = 0; i < r.forced.size() && i < 100; ++i)
      forced.push_back({{"hex", r.forced[i].hex},
                        {"corner", r.forced[i].corner},
                        {"kind", std::string(to_string(r.forced[i].kind))},
                        {"scaled_jacobian", r.forced[i].scaled_jacobian}});
    j["pillow"] = {{"forced", p.forced},
                   {"flat_doublets", p.flat_doublets},
                   {"concave_corners", p.concave_corners},
                   {"fixed_corners", p.fixed_corners},
                   {"collinear", p.collinear},
                   {"forced_list", forced},
                   {"forced_after", p.forced_after},
                   {"excluded_vertices", p.excluded_vertices},
                   {"dropped_hexes", p.dropped_hexes},
                   {"unserved_vertices", p.unserved_vertices},
                   {"shrink_set", p.shrink_set},
                   {"new_hexes", p.new_hexes},
                   {"new_vertices", p.new_vertices},
                   {"whole_boundary", p.whole_boundary},
                   {"passes", p.passes}};
    auto retry_json = [](const PillowRetryStats& pr, bool repair) {
      nlohmann::json o = {{"tried", pr.tried}, {"kept", pr.kept}};
      if (!pr.tried) return o;
      if (repair) {
        o["rounds"] = pr.rounds;
        o["rounds_kept"] = pr.rounds_kept;
        o["seed_hexes"] = pr.seed_hexes;
        o["new_hexes"] = pr.new_hexes;
        o["whole"] = pr.whole;
        o["whole_kept"] = pr.whole_kept;
      } else {
        o["forced_sj"] = pr.forced_sj;
        o["forced_min_sj"] = pr.forced_min_sj;
      }
      o["first"] = {{"hexes", pr.first_hexes},
                    {"min_sj", pr.first_min_sj},
                    {"mean_sj", pr.first_mean_sj},
                    {"nonpositive", pr.first_nonpositive}};
      o["retry"] = pr.retry_ok ? nlohmann::json{{"hexes", pr.retry_hexes},
                                                {"min_sj", pr.retry_min_sj},
                                                {"mean_sj", pr.retry_mean_sj},
                                                {"nonpositive", pr.retry_nonpositive}}
                               : nlohmann::json(nullptr);
      return o;
    };
    j["pillow_retry"] = retry_json(r.pillow_retry, false);
    j["pillow_repair"] = retry_json(r.pillow_repair, true);
    const UntangleStats& u = r.untangle;
    auto phase = [](const UntanglePhaseStats& s) {
      return nlohmann::json{{"rounds", s.rounds},
                            {"iterations", s.iterations},
                            {"evaluations", s.evaluations},
                            {"corner_evaluations", s.corner_evaluations},
                            {"time_s", s.time_s},
                            {"min_sj_before", s.min_sj_before},
                            {"min_sj_after", s.min_sj_after},
                            {"nonpositive_before", s.nonpositive_before},
                            {"nonpositive_after", s.nonpositive_after}};
    };
    j["untangle"] = {{"method", std::string(to_string(u.solver))},
                     {"free_vertices", u.free_vertices},
                     {"active_corners", u.active_corners},
                     {"forced_corners", u.forced_corners},
                     {"forced_nonpositive", u.forced_nonpositive},
                     {"forced_min_sj", std::isfinite(u.forced_min_sj) ? nlohmann::json(u.forced_min_sj)
                                                                       : nlohmann::json(nullptr)},
                     {"eps_rule", std::string(to_string(u.eps_rule))},
                     {"stalled", u.stalled},
                     {"continuation_run", u.continuation_run},
                     {"continuation_used", u.continuation_used},
                     {"direct_nonpositive", u.direct_nonpositive},
                     {"direct_rounds", u.direct_rounds},
                     {"final_eps", u.final_eps},
                     {"untangle", phase(u.untangle)},
                     {"optimize", phase(u.optimize)},
                     {"restarts_ended_slow", u.restarts_ended_slow},
                     {"optimize_restarts_dropped", u.optimize_restarts_dropped},
                     {"optimize_reverted", u.optimize_reverted},
                     {"mean_polish_kept", u.mean_polish_kept},
                     {"local_moves", u.local_moves},
                     {"quality_passes", u.quality_passes},
                     {"final_polish_runs", u.final_polish_runs},
                     {"final_polish_kept", u.final_polish_kept},
                     {"final_polish_rounds", u.final_polish_rounds},
                     {"time_s", u.time_s}};
  }
  j["timings_s"] = {{"check", r.timings.check_s},
                    {"elimination", r.timings.elimination_s},
                    {"reconstruction", r.timings.reconstruction_s},
                    {"pillow", r.timings.pillow_s},
                    {"placement", r.timings.placement_s},
                    {"untangle", r.timings.untangle_s},
                    {"quality", r.timings.quality_s},
                    {"pillow_retry", r.timings.pillow_retry_s},
                    {"intrusion_cover", r.timings.intrusion_cover_s},
                    {"other_orders", r.timings.other_orders_s}};
  return j;
}

nlohmann::json effort_to_json(const MeshParams& p) {
  return {{"plan_budget_s", p.planner.budget_s},
          {"improve_budget_s", p.planner.improve_budget_s},
          {"stuck_fill_budget_s", p.terminal.total_budget_s},
          {"quality_passes", p.untangle.quality_passes},
          {"final_polish_runs", p.untangle.final_polish_runs},
          {"final_polish_rounds", p.untangle.final_polish_rounds},
          {"alternatives", p.alternatives},
          {"alternatives_always", p.alternatives_always},
          {"repair_rounds", p.repair_rounds},
          {"intrusion_flip_rounds", p.intrusion_flip_rounds}};
}

}  // namespace hexpeel
