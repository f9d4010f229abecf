// Greedy dual cycle elimination (paper section 3.4) in the order of an OrderPolicy.
//
// Every step ranks the remaining chords by their quick keys, tests them for feasibility in that
// order, rates feasible ones fully (re-queueing those whose full key is larger) and collapses
// the first whose full key is still the smallest. Deterministic: keys end with the chord id.
//
// Input: a fresh EliminationState of a valid surface. Output: the plan, or `stuck` with the
// reasons every remaining chord is infeasible.
#include "hexpeel/elimination.h"

#include <chrono>
#include <cstdio>
#include <queue>
#include <tuple>

namespace hexpeel {
namespace {

std::string stuck_text(const StuckReport& r) {
  std::string text = std::to_string(r.quads_left) + " quads and " + std::to_string(r.chords_left) +
                     " chords left; no chord can be eliminated:";
  for (size_t i = 0; i < r.reasons.size(); ++i)
    if (r.reasons[i] > 0)
      text += " " + std::to_string(r.reasons[i]) + " × " +
              std::string(to_string(static_cast<Infeasible>(i))) + ";";
  if (!text.empty() && text.back() == ';') text.back() = '.';
  return text;
}

}  // namespace

StuckReport diagnose_stuck(const EliminationState& state) {
  StuckReport r;
  r.quads_left = state.alive_quads();
  r.chords_left = state.alive_chords();
  for (int32_t c = 0; c < state.num_chords(); ++c)
    if (state.chord_alive(c)) ++r.reasons[static_cast<size_t>(state.feasibility(c).why)];
  r.text = stuck_text(r);
  return r;
}

Status check_simple_chords(const EliminationState& state) {
  const ChordSet& chords = state.chord_set();
  for (size_t c = 0; c < chords.chords.size(); ++c)
    if (chords.chords[c].self_intersecting)
      return Status::error(StatusCode::self_intersecting_chord,
                           "chord " + std::to_string(c) +
                               " passes through a quad twice; dual cycle elimination needs every "
                               "chord to be simple");
  return Status::success();
}

EliminationPlan run_elimination(EliminationState& state, const EliminationParams& params,
                                const Context& ctx) {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  EliminationPlan plan;
  const int32_t nchords = state.num_chords();
  const int32_t total_steps = std::max(1, nchords - 3);

  plan.status = check_simple_chords(state);
  if (!plan.status.ok()) return plan;

  plan.stats.predicted_hexes = 1;
  const OrderPolicy policy(params.order);
  while (state.alive_chords() > 3) {
    if (params.time_limit_s > 0 &&
        std::chrono::duration<double>(clock::now() - t0).count() > params.time_limit_s) {
      plan.status = Status::error(StatusCode::stuck, "time limit reached during elimination");
      plan.stats.timed_out = true;
      break;
    }
    // Min-heap on (key, is_full): a chord's full key is never smaller than its quick key.
    using Entry = std::pair<Move, bool>;
    auto later = [](const Entry& x, const Entry& y) {
      return std::tie(x.first.key, x.second) > std::tie(y.first.key, y.second);
    };
    std::priority_queue<Entry, std::vector<Entry>, decltype(later)> heap(later);
    for (int32_t c = 0; c < nchords; ++c)
      if (state.chord_alive(c)) heap.push({policy.quick(state, c), false});
    bool chosen = false;
    while (!heap.empty()) {
      auto [move, is_full] = heap.top();
      heap.pop();
      if (!is_full) {
        ++plan.stats.feasibility_tests;
        auto f = state.feasibility(move.chord);
        if (!f.ok()) continue;
        heap.push({policy.full(state, move.chord, f.sides), true});
        continue;
      }
      PlanStep step = state.apply(move.chord, move.side);
      step.concave = move.concave;
      step.flat = move.flat;
      step.priority = -move.key[1];
      plan.stats.predicted_hexes += (move.concave ? -1 : 1) * static_cast<int64_t>(step.side_quads.size());
      plan.stats.flat_steps += step.flat;
      plan.stats.concave_steps += step.concave;
      plan.steps.push_back(std::move(step));
      chosen = true;
      break;
    }
    if (!chosen) {
      plan.stuck = diagnose_stuck(state);
      plan.status = Status::error(StatusCode::stuck,
                                  "elimination stuck after " + std::to_string(plan.steps.size()) +
                                      " steps: " + plan.stuck.text);
      break;
    }
    ctx.report("elimination", static_cast<double>(plan.steps.size()) / total_steps);
  }
  plan.stats.steps = static_cast<int32_t>(plan.steps.size());
  plan.stats.time_s = std::chrono::duration<double>(clock::now() - t0).count();
  if (!plan.status.ok()) return plan;
  std::vector<int32_t> ids;
  QuadSurface cube = state.current_surface(&ids);
  if (cube.num_quads() != 6 || cube.num_points() != 8) {
    plan.status = Status::error(StatusCode::internal_error,
                                "elimination ended with 3 chords but " +
                                    std::to_string(cube.num_quads()) + " quads");
    return plan;
  }
  plan.final_quads = ids;
  for (int32_t q : ids) plan.final_corners.push_back(state.corners(q));
  return plan;
}

}  // namespace hexpeel
