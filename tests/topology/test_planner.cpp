// Tests of the planner: it finds complete plans where greedy elimination gets stuck, is
// deterministic for a seed, and its plans on generated families stay close to the hex count of
// the generator's known mesh. Prints the success rate and hex-count ratios (figures, not timing).
#include "hexpeel/chords.h"
#include "hexpeel/elimination.h"
#include "hexpeel/planner.h"
#include "hexpeel/reconstruction.h"
#include "support/generators.h"
#include "support/prepared.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>
#include <thread>

using namespace hexpeel;
namespace ht = hexpeel::testing;

namespace {

using ht::Prepared;
using ht::prepare;

PlannerParams convex_only() {
  // The planner's own behaviour, without concave steps (their intrusions are tested elsewhere).
  PlannerParams pp;
  pp.order.concave = false;
  pp.budget_s = 20.0;
  return pp;
}

bool greedy_gets_stuck(const Prepared& p) {
  EliminationState st(p.surface, p.chords, p.edges);
  EliminationParams ep;
  ep.order.method = Method::original;
  ep.order.side_rule = SideRule::heavier;
  return run_elimination(st, ep).status.code == StatusCode::stuck;
}

}  // namespace

TEST(Planner, PlansAreCompleteAndReconstructible) {
  int planned = 0, rescued = 0, total = 0;
  std::vector<double> ratios;
  std::string failures;
  for (uint64_t seed = 1; seed <= 16; ++seed) {
    ht::Generated g = seed % 2 ? ht::pillowed(ht::random_voxel_solid(seed, 4, 10, 2), seed, 0.3)
                               : ht::random_voxel_solid(seed, 5, 8 + 2 * static_cast<int>(seed), 1);
    ASSERT_GT(g.surface.num_quads(), 0) << g.name;
    Prepared p = prepare(g.surface);
    ++total;
    bool stuck = greedy_gets_stuck(p);
    EliminationState st(p.surface, p.chords, p.edges);
    PlannerResult r = run_planner(st, convex_only());
    if (!r.plan.status.ok()) {
      failures += " " + g.name + "(" + to_string(r.plan.status) + ")";
      continue;
    }
    ++planned;
    rescued += stuck;
    ReconstructionParams rp;
    rp.verify_each_step = true;
    ReconstructionResult rec = run_reconstruction(p.surface, r.plan, rp, {}, &st);
    ASSERT_TRUE(rec.status.ok()) << g.name << ": " << to_string(rec.status);
    EXPECT_EQ(rec.stats.hexes, r.plan.stats.predicted_hexes) << g.name;
    ratios.push_back(static_cast<double>(rec.stats.hexes) / g.known_mesh.num_hexes());
  }
  std::sort(ratios.begin(), ratios.end());
  std::printf("planner: %d of %d planned (%d where greedy got stuck); hexes / generator's: "
              "median %.2f, max %.2f;%s%s\n",
              planned, total, rescued, ratios.empty() ? 0.0 : ratios[ratios.size() / 2],
              ratios.empty() ? 0.0 : ratios.back(), failures.empty() ? "" : " failed:", failures.c_str());
  EXPECT_EQ(planned, total) << failures;
}

TEST(Planner, SameSeedSamePlan) {
  ht::Generated g = ht::pillowed(ht::random_voxel_solid(3, 4, 10, 2), 3, 0.3);
  Prepared p = prepare(g.surface);
  auto plan_of = [&] {
    EliminationState st(p.surface, p.chords, p.edges);
    PlannerResult r = run_planner(st, convex_only());
    std::vector<std::pair<int32_t, int>> steps;
    for (const PlanStep& s : r.plan.steps) steps.push_back({s.chord, s.side});
    return steps;
  };
  auto a = plan_of();
  EXPECT_FALSE(a.empty());
  EXPECT_EQ(a, plan_of());
}

TEST(Planner, CubeGridGetsItsGrid) {
  for (int n = 2; n <= 4; ++n) {
    ht::Generated g = ht::cube(n, n + 1, n);
    Prepared p = prepare(g.surface);
    EliminationState st(p.surface, p.chords, p.edges);
    PlannerResult r = run_planner(st, convex_only());
    ASSERT_TRUE(r.plan.status.ok()) << to_string(r.plan.status);
    EXPECT_EQ(r.plan.stats.predicted_hexes, n * (n + 1) * n);
  }
}

TEST(Planner, ConflictSearchRescuesStuckGreedy) {
  // Without windowed backtracking (window 0), a stuck greedy descent leaves everything to the
  // conflict-directed restarts: their plans must be complete and reconstruct exactly.
  int stuck = 0, rescued = 0;
  for (uint64_t seed = 1; seed <= 24; ++seed) {
    ht::Generated g = seed % 2 ? ht::pillowed(ht::random_voxel_solid(seed, 4, 10, 2), seed, 0.3)
                               : ht::random_voxel_solid(seed, 5, 8 + 2 * static_cast<int>(seed), 1);
    Prepared p = prepare(g.surface);
    PlannerParams pp = convex_only();
    pp.window = 0;
    pp.improve = false;
    EliminationState st(p.surface, p.chords, p.edges);
    PlannerResult r = run_planner(st, pp);
    if (r.stats.stuck_events == 0) continue;
    ++stuck;
    ASSERT_TRUE(r.plan.status.ok()) << g.name << ": " << to_string(r.plan.status);
    EXPECT_EQ(r.stats.strategy, "conflict") << g.name;
    ReconstructionParams rp;
    rp.verify_each_step = true;
    ReconstructionResult rec = run_reconstruction(p.surface, r.plan, rp, {}, &st);
    ASSERT_TRUE(rec.status.ok()) << g.name << ": " << to_string(rec.status);
    EXPECT_EQ(rec.stats.hexes, r.plan.stats.predicted_hexes) << g.name;
    ++rescued;
  }
  std::printf("conflict search: %d of %d stuck greedy descents rescued\n", rescued, stuck);
  EXPECT_GT(stuck, 0) << "no surface made greedy stuck: the test shows nothing";
}

TEST(Planner, BudgetCountsWorkNotTime) {
  // The budget is work, not wall-clock time: a search slowed down (here by a progress callback
  // that sleeps) must explore exactly as far and keep the same plan when its budget runs out.
  // The first generated surface whose greedy descent gets stuck (so the improve phase runs).
  std::optional<Prepared> p;
  for (uint64_t seed = 1; seed <= 24 && !p; ++seed) {
    ht::Generated g = seed % 2 ? ht::pillowed(ht::random_voxel_solid(seed, 4, 10, 2), seed, 0.3)
                               : ht::random_voxel_solid(seed, 5, 8 + 2 * static_cast<int>(seed), 1);
    Prepared q = prepare(g.surface);
    EliminationState st(q.surface, q.chords, q.edges);
    const PlannerResult r = run_planner(st, convex_only());
    if (r.stats.stuck_events > 0 && r.plan.status.ok() && r.stats.strategy == "window") p = std::move(q);
  }
  ASSERT_TRUE(p) << "no surface made greedy stuck: the improve budget is never used";
  PlannerParams pp = convex_only();
  pp.improve_budget_s = 0.002;
  auto run = [&](const Context& ctx, std::vector<std::pair<int32_t, int>>& steps) {
    EliminationState st(p->surface, p->chords, p->edges);
    PlannerResult r = run_planner(st, pp, ctx);
    for (const PlanStep& s : r.plan.steps) steps.push_back({s.chord, s.side});
    return r.stats;
  };
  std::vector<std::pair<int32_t, int>> fast_steps, slow_steps;
  const PlannerStats fast = run({}, fast_steps);
  Context slow_ctx;
  int64_t sleeps = 0;
  slow_ctx.progress = [&sleeps](std::string_view, double) {
    ++sleeps;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  };
  const PlannerStats slow = run(slow_ctx, slow_steps);
  std::printf("budget test: %lld nodes, %d plans, fast %.3f s, slow %.3f s\n",
              static_cast<long long>(fast.nodes), static_cast<int>(fast.plans_tried), fast.time_s,
              slow.time_s);
  EXPECT_TRUE(fast.budget_exhausted) << "the budget did not run out: the test shows nothing";
  EXPECT_GT(sleeps, 20) << "the slowdown did not slow the search";
  EXPECT_EQ(slow.nodes, fast.nodes);
  EXPECT_EQ(slow.plans_tried, fast.plans_tried);
  EXPECT_EQ(slow_steps, fast_steps);
}
