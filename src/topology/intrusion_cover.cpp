// Intrusion cover (see intrusion_cover.h).
#include "hexpeel/intrusion_cover.h"

#include <algorithm>
#include <chrono>

namespace hexpeel {
namespace {

/// Applies covering steps on `state` for the quads with pending > 0 (virtual layers still to be
/// laid), each the smallest usable side that holds some of them while its chord keeps off them
/// and their edge neighbours; every pending quad on the chosen side loses one layer. Returns the
/// steps applied (in order).
std::vector<PlanStep> add_covers(EliminationState& state, std::vector<int32_t>& pending) {
  std::vector<PlanStep> out;
  const int32_t nq = static_cast<int32_t>(pending.size());
  std::vector<uint8_t> near(nq, 0);
  std::vector<ChordStep> passages;
  std::vector<int32_t> side;
  while (true) {
    std::fill(near.begin(), near.end(), 0);
    bool any = false;
    for (int32_t q = 0; q < nq; ++q) {
      if (pending[q] <= 0 || !state.quad_alive(q)) continue;
      any = true;
      near[q] = 1;
      for (int k = 0; k < 4; ++k) near[state.opposite(4 * q + k) / 4] = 1;
    }
    if (!any) break;
    int32_t best = -1, best_side = -1, best_size = nq + 1;
    for (int32_t c = 0; c < state.num_chords(); ++c) {
      if (!state.chord_alive(c)) continue;
      state.chord_steps(c, passages);
      if (std::any_of(passages.begin(), passages.end(), [&](const ChordStep& p) { return near[p.quad] != 0; }))
        continue;
      const int32_t smaller = std::min(state.side_size(c, 0), state.side_size(c, 1));
      if (smaller >= best_size && std::max(state.side_size(c, 0), state.side_size(c, 1)) >= best_size)
        continue;
      const auto f = state.feasibility(c);
      if (!f.ok()) continue;
      for (int s = 0; s < 2; ++s) {
        const int32_t size = state.side_size(c, s);
        if (!f.sides[s] || size >= best_size) continue;
        state.side_region(c, s, side);
        if (std::any_of(side.begin(), side.end(), [&](int32_t q) { return pending[q] > 0; })) {
          best = c;
          best_side = s;
          best_size = size;
        }
      }
    }
    if (best < 0) break;
    const bool flat = state.weights(best).crossing_sharp == 0;
    PlanStep ps = state.apply(best, static_cast<int>(best_side));
    ps.flat = flat;
    for (int32_t q : ps.side_quads)
      if (pending[q] > 0) --pending[q];
    out.push_back(std::move(ps));
  }
  return out;
}

/// Replays plan step b on `state` and appends it to out's steps with b's flags, towards b's other
/// side as a convex step when `flip` and that side is usable. False, with an internal error in
/// out.status, when b cannot be replayed (its chord gone or infeasible, its side unusable).
bool replay_step(EliminationState& state, const PlanStep& b, bool flip, EliminationPlan& out) {
  const auto f = state.chord_alive(b.chord) ? state.feasibility(b.chord)
                                             : EliminationState::Feasibility{};
  if (!state.chord_alive(b.chord) || !f.ok() || !f.sides[b.side]) {
    out.status = Status::error(StatusCode::internal_error,
                               "a step of the plan cannot be replayed (chord " +
                                   std::to_string(b.chord) + ")");
    return false;
  }
  const bool other = flip && f.sides[1 - b.side];
  PlanStep ps = state.apply(b.chord, other ? 1 - b.side : b.side);
  ps.concave = b.concave && !other;
  ps.flat = b.flat;
  ps.priority = b.priority;
  out.steps.push_back(std::move(ps));
  return true;
}

/// out's final surface (the one `state` holds after its steps) and its stats' step counts.
/// A plan that ends on a filled stuck surface starts from that fill's hexes, not one cube.
void close_plan(const EliminationState& state, EliminationPlan& out) {
  state.current_surface(&out.final_quads);
  out.final_corners.clear();
  for (int32_t q : out.final_quads) out.final_corners.push_back(state.corners(q));
  out.stats.steps = static_cast<int32_t>(out.steps.size());
  out.stats.predicted_hexes =
      out.terminal.empty() ? 1 : static_cast<int64_t>(out.terminal.hexes.size());
  out.stats.concave_steps = out.stats.flat_steps = 0;
  for (const PlanStep& s : out.steps) {
    out.stats.predicted_hexes += (s.concave ? -1 : 1) * static_cast<int64_t>(s.side_quads.size());
    out.stats.concave_steps += s.concave;
    out.stats.flat_steps += s.flat;
  }
}

/// cover_concave_steps without the timing.
EliminationPlan rebuild(EliminationState& state, const EliminationPlan& plan,
                        const PlannerParams& params, const Context& ctx,
                        IntrusionCoverStats& stats, int max_replans) {
  EliminationPlan out;
  std::vector<PlanStep> todo = plan.steps;  // the plan being replayed
  size_t pos = 0;
  // Virtual layers still to be covered, per input quad (the state is fresh: all quads alive).
  std::vector<int32_t> pending(static_cast<size_t>(state.alive_quads()), 0);
  double replan_effort = 0.0;  // budget seconds the replans used
  out.status = Status::success();
  while (true) {
    // Replay up to the end of the next run of concave steps.
    bool in_run = false;
    for (; pos < todo.size(); ++pos) {
      const PlanStep& b = todo[pos];
      if (in_run && !b.concave) break;
      if (!replay_step(state, b, false, out)) return out;
      if (out.steps.back().concave) {
        in_run = true;
        for (int32_t q : out.steps.back().side_quads) ++pending[q];
      }
    }
    if (!in_run) break;  // replayed to the end
    std::vector<PlanStep> covers;
    if (stats.replans < max_replans) covers = add_covers(state, pending);
    for (int32_t q = 0; q < static_cast<int32_t>(pending.size()); ++q) {
      if (pending[q] > 0 && state.quad_alive(q)) ++stats.uncovered_quads;
      pending[q] = 0;
    }
    if (covers.empty()) continue;  // the state is the plan's own: go on replaying it
    stats.cover_steps += static_cast<int32_t>(covers.size());
    for (auto& c : covers) out.steps.push_back(std::move(c));
    ++stats.replans;
    // The replans share the budget the whole plan has (what the first search left is not
    // known here, so all replans together get one budget), and flat steps keep the input's
    // penalty (the planner would take the quads left).
    PlannerParams rp = params;
    rp.budget_s = params.budget_s - replan_effort;
    rp.improve_budget_s = std::min(params.improve_budget_s, rp.budget_s);
    if (rp.flat_penalty <= 0) rp.flat_penalty = static_cast<double>(pending.size());
    if (!(rp.budget_s > 0)) {
      out.status = Status::error(StatusCode::stuck, "intrusion cover: the replans used up the plan budget");
      return out;
    }
    PlannerResult rest = run_planner(state, rp, ctx);
    replan_effort += rest.stats.effort_s;
    stats.replan_effort_s = replan_effort;
    if (!rest.plan.status.ok()) {
      out.status = rest.plan.status;
      return out;
    }
    // run_planner left its plan applied: undo it and replay it in the loop.
    for (size_t i = 0; i < rest.plan.steps.size(); ++i) state.undo();
    todo = std::move(rest.plan.steps);
    pos = 0;
  }
  out.stats = plan.stats;
  close_plan(state, out);
  if (out.final_quads.size() != 6) {
    out.status = Status::error(StatusCode::internal_error, "intrusion cover: the plan did not end on a cube");
    return out;
  }
  stats.predicted_hexes = out.stats.predicted_hexes;
  return out;
}

}  // namespace

EliminationPlan cover_concave_steps(EliminationState& state, const EliminationPlan& plan,
                                    const PlannerParams& params, const Context& ctx,
                                    IntrusionCoverStats& stats, int max_replans) {
  const auto t0 = std::chrono::steady_clock::now();
  stats.tried = true;
  EliminationPlan out = rebuild(state, plan, params, ctx, stats, max_replans);
  stats.time_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

EliminationPlan flip_refused_steps(EliminationState& state, const EliminationPlan& plan,
                                   const std::vector<int32_t>& refused, int32_t& flipped) {
  flipped = 0;
  EliminationPlan out;
  out.terminal = plan.terminal;
  out.stats = plan.stats;
  const int32_t n = static_cast<int32_t>(plan.steps.size());
  std::vector<uint8_t> flip(n, 0);
  for (int32_t i : refused)
    if (i >= 0 && i < n && plan.steps[i].concave) flip[i] = 1;
  for (int32_t i = 0; i < n; ++i) {
    if (!replay_step(state, plan.steps[i], flip[i] != 0, out)) return out;
    flipped += out.steps.back().side != plan.steps[i].side;
  }
  close_plan(state, out);
  out.status = Status::success();
  return out;
}

}  // namespace hexpeel
