// Greedy dual cycle elimination in Müller-Hannemann's order (paper section 3.4).
//
// Every step rates the remaining simple chords by their side weights (sharp parallel edges per
// chord length), takes the best feasible one and collapses it on its heavier usable side; flat
// chords (crossing no sharp edge) come last, only when nothing else is feasible. Ties: equal
// weight -> shorter chord -> smaller chord id; equal side weights -> the side with fewer quads
// (fewer hexes), then the left side. Deterministic.
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

struct Candidate {
  int flat;        // 1 = flat chord (last resort)
  double weight;   // larger first
  int32_t length;  // shorter first
  int32_t chord;   // smaller first
  std::array<bool, 2> sides;  // sides the rating assumed usable

  bool operator>(const Candidate& o) const {
    return std::make_tuple(flat, -weight, length, chord) >
           std::make_tuple(o.flat, -o.weight, o.length, o.chord);
  }
};

Candidate rate(const ChordWeights& w, int32_t chord, std::array<bool, 2> sides) {
  double best = -1.0;
  for (int s = 0; s < 2; ++s)
    if (sides[s]) best = std::max(best, w.sharp[s]);
  return {w.crossing_sharp == 0 ? 1 : 0, best, w.length, chord, sides};
}

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

EliminationPlan run_elimination(EliminationState& state, const EliminationParams& params,
                                const Context& ctx) {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  EliminationPlan plan;
  const int32_t nchords = state.num_chords();
  const int32_t total_steps = std::max(1, nchords - 3);

  for (int32_t c = 0; c < nchords; ++c)
    if (state.feasibility(c).why == Infeasible::self_intersecting) {
      plan.status = Status::error(StatusCode::self_intersecting_chord,
                                  "chord " + std::to_string(c) +
                                      " passes through a quad twice; dual cycle elimination needs "
                                      "every chord to be simple");
      return plan;
    }

  plan.stats.predicted_hexes = 1;
  std::vector<int32_t> region;
  while (state.alive_chords() > 3) {
    if (params.time_limit_s > 0 &&
        std::chrono::duration<double>(clock::now() - t0).count() > params.time_limit_s) {
      plan.status = Status::error(StatusCode::stuck, "time limit reached during elimination");
      break;
    }
    std::priority_queue<Candidate, std::vector<Candidate>, std::greater<>> heap;
    for (int32_t c = 0; c < nchords; ++c)
      if (state.chord_alive(c)) heap.push(rate(state.weights(c), c, {true, true}));
    bool chosen = false;
    while (!heap.empty()) {
      Candidate cand = heap.top();
      heap.pop();
      ++plan.stats.feasibility_tests;
      auto f = state.feasibility(cand.chord);
      if (!f.ok()) continue;
      if (f.sides != cand.sides) {  // re-rate with the usable sides only
        heap.push(rate(state.weights(cand.chord), cand.chord, f.sides));
        continue;
      }
      ChordWeights w = state.weights(cand.chord);
      int side;
      if (f.sides[0] && f.sides[1] && w.sharp[0] == w.sharp[1]) {
        state.side_region(cand.chord, 0, region);
        size_t left = region.size();
        state.side_region(cand.chord, 1, region);
        side = region.size() < left ? 1 : 0;
      } else if (f.sides[0] && f.sides[1]) {
        side = w.sharp[0] > w.sharp[1] ? 0 : 1;
      } else {
        side = f.sides[0] ? 0 : 1;
      }
      PlanStep step = state.apply(cand.chord, side);
      step.priority = w.sharp[side];
      step.flat = cand.flat != 0;
      plan.stats.predicted_hexes += static_cast<int64_t>(step.side_quads.size());
      plan.stats.flat_steps += step.flat;
      plan.steps.push_back(std::move(step));
      chosen = true;
      break;
    }
    if (!chosen) {
      StuckReport& r = plan.stuck;
      r.quads_left = state.alive_quads();
      r.chords_left = state.alive_chords();
      for (int32_t c = 0; c < nchords; ++c)
        if (state.chord_alive(c)) ++r.reasons[static_cast<size_t>(state.feasibility(c).why)];
      r.text = stuck_text(r);
      plan.status = Status::error(StatusCode::stuck,
                                  "elimination stuck after " + std::to_string(plan.steps.size()) +
                                      " steps: " + r.text);
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
