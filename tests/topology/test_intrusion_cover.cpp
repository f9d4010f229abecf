// Intrusion cover (intrusion_cover.h): a plan whose step after its concave steps crosses the
// concavity's floor refuses those intrusions; the rebuilt plan covers the floor first and
// intrudes them all. Plans without refused intrusions are not the cover's business, but a plan
// without concave steps must come back step for step.
#include "hexpeel/intrusion_cover.h"
#include "hexpeel/planner.h"
#include "hexpeel/reconstruction.h"
#include "support/generators.h"
#include "support/prepared.h"

#include <gtest/gtest.h>

#include <algorithm>

using namespace hexpeel;
namespace ht = hexpeel::testing;

namespace {

/// A 5x5x4 block of voxels with a well of 3x3 voxels, `depth` deep, open at the top.
ht::Generated well(int depth, int m) {
  std::vector<uint8_t> filled(5 * 5 * 4, 1);
  for (int k = 4 - depth; k < 4; ++k)
    for (int j = 1; j < 4; ++j)
      for (int i = 1; i < 4; ++i) filled[i + 5 * (j + 5 * k)] = 0;
  return ht::voxel_solid(5, 5, 4, filled, m, "well");
}

/// The planner's plan, but right after its first run of concave steps a chord that crosses the
/// floor they left is eliminated, and the rest is planned again. `state` is fresh and holds the
/// plan's end afterwards. Empty steps when the plan has no concave step or no such chord exists.
EliminationPlan crossing_plan(EliminationState& state) {
  EliminationPlan good;
  {
    EliminationState first(state);
    good = run_planner(first, {}).plan;
  }
  EliminationPlan bad;
  if (!good.status.ok()) return bad;
  std::vector<uint8_t> floor(static_cast<size_t>(state.alive_quads()), 0);
  size_t i = 0;
  while (i < good.steps.size() && !good.steps[i].concave) bad.steps.push_back(state.apply(good.steps[i].chord, good.steps[i].side)), ++i;
  for (; i < good.steps.size() && good.steps[i].concave; ++i) {
    PlanStep ps = state.apply(good.steps[i].chord, good.steps[i].side);
    ps.concave = true;
    for (int32_t q : ps.side_quads) floor[q] = 1;
    bad.steps.push_back(std::move(ps));
  }
  if (bad.steps.empty() || !bad.steps.back().concave) return EliminationPlan{};
  std::vector<ChordStep> passages;
  for (int32_t c = 0; c < state.num_chords(); ++c) {
    if (!state.chord_alive(c)) continue;
    state.chord_steps(c, passages);
    const bool crosses = std::any_of(passages.begin(), passages.end(),
                                     [&](const ChordStep& p) { return floor[p.quad] != 0; });
    const auto f = state.feasibility(c);
    if (!crosses || !f.ok()) continue;
    bad.steps.push_back(state.apply(c, f.sides[0] ? 0 : 1));
    PlannerResult rest = run_planner(state, {});
    if (!rest.plan.status.ok()) return EliminationPlan{};
    for (auto& s : rest.plan.steps) bad.steps.push_back(std::move(s));
    bad.final_quads = rest.plan.final_quads;
    bad.final_corners = rest.plan.final_corners;
    bad.status = Status::success();
    return bad;
  }
  return EliminationPlan{};
}

int32_t concave_steps(const EliminationPlan& plan) {
  return static_cast<int32_t>(std::count_if(plan.steps.begin(), plan.steps.end(),
                                            [](const PlanStep& s) { return s.concave; }));
}

}  // namespace

TEST(IntrusionCover, CoversTheFloorACrossingChordSpoilt) {
  for (int m : {1, 2}) {
    SCOPED_TRACE("m = " + std::to_string(m));
    ht::Generated g = well(3, m);
    ASSERT_FALSE(g.surface.quads.empty());
    ht::Prepared p = ht::prepare(g.surface);
    EliminationState bad_state(p.surface, p.chords, p.edges);
    EliminationPlan bad = crossing_plan(bad_state);
    ASSERT_TRUE(bad.status.ok()) << "no concave run followed by a crossing chord";
    ASSERT_GT(concave_steps(bad), 0);
    ReconstructionResult spoilt = run_reconstruction(p.surface, bad, {}, {}, &bad_state);
    ASSERT_TRUE(spoilt.status.ok()) << spoilt.status.message;
    ASSERT_FALSE(spoilt.stats.invalid_intrusion_steps.empty())
        << "the crossing chord should leave the floor unfit for intrusion";

    EliminationState state(p.surface, p.chords, p.edges);
    IntrusionCoverStats stats;
    EliminationPlan covered = cover_concave_steps(state, bad, {}, {}, stats);
    ASSERT_TRUE(covered.status.ok()) << covered.status.message;
    EXPECT_TRUE(stats.tried);
    EXPECT_GE(stats.cover_steps, 1);
    EXPECT_GE(stats.replans, 1);
    EXPECT_EQ(stats.uncovered_quads, 0);
    EXPECT_EQ(concave_steps(covered), concave_steps(bad));
    EXPECT_EQ(covered.stats.concave_steps, concave_steps(bad));
    ASSERT_EQ(covered.final_quads.size(), 6u);
    ReconstructionResult rec = run_reconstruction(p.surface, covered, {}, {}, &state);
    ASSERT_TRUE(rec.status.ok()) << rec.status.message;
    EXPECT_TRUE(rec.stats.invalid_intrusion_steps.empty());
    EXPECT_EQ(rec.stats.intrusions, concave_steps(bad));
    EXPECT_EQ(static_cast<int64_t>(rec.complex.hexes.size()), covered.stats.predicted_hexes);
    EXPECT_EQ(stats.predicted_hexes, covered.stats.predicted_hexes);
  }
}

TEST(IntrusionCover, APlanWithoutConcaveStepsComesBackAsItWas) {
  ht::Prepared p = ht::prepare(ht::cube(3, 3, 3).surface);
  EliminationState first(p.surface, p.chords, p.edges);
  EliminationPlan plan = run_planner(first, {}).plan;
  ASSERT_TRUE(plan.status.ok());
  ASSERT_EQ(concave_steps(plan), 0);
  EliminationState state(p.surface, p.chords, p.edges);
  IntrusionCoverStats stats;
  EliminationPlan same = cover_concave_steps(state, plan, {}, {}, stats);
  ASSERT_TRUE(same.status.ok()) << same.status.message;
  ASSERT_EQ(same.steps.size(), plan.steps.size());
  for (size_t i = 0; i < plan.steps.size(); ++i) {
    EXPECT_EQ(same.steps[i].chord, plan.steps[i].chord);
    EXPECT_EQ(same.steps[i].side, plan.steps[i].side);
    EXPECT_EQ(same.steps[i].side_quads, plan.steps[i].side_quads);
  }
  EXPECT_EQ(same.final_quads, plan.final_quads);
  EXPECT_EQ(stats.cover_steps, 0);
  EXPECT_EQ(stats.replans, 0);
}

TEST(IntrusionFlip, TurnsTheRefusedStepsToTheirOtherSide) {
  for (int m : {1, 2}) {
    SCOPED_TRACE("m = " + std::to_string(m));
    ht::Prepared p = ht::prepare(well(3, m).surface);
    EliminationState bad_state(p.surface, p.chords, p.edges);
    EliminationPlan bad = crossing_plan(bad_state);
    ASSERT_TRUE(bad.status.ok()) << "no concave run followed by a crossing chord";
    ReconstructionResult spoilt = run_reconstruction(p.surface, bad, {}, {}, &bad_state);
    ASSERT_TRUE(spoilt.status.ok()) << spoilt.status.message;
    const std::vector<int32_t>& refused = spoilt.stats.invalid_intrusion_steps;
    ASSERT_FALSE(refused.empty());

    EliminationState state(p.surface, p.chords, p.edges);
    int32_t flipped = 0;
    EliminationPlan flip = flip_refused_steps(state, bad, refused, flipped);
    ASSERT_TRUE(flip.status.ok()) << flip.status.message;
    EXPECT_EQ(flipped, static_cast<int32_t>(refused.size()));
    ASSERT_EQ(flip.steps.size(), bad.steps.size());
    int64_t hexes = 1;
    for (size_t i = 0; i < bad.steps.size(); ++i) {
      const bool was_refused = std::find(refused.begin(), refused.end(), static_cast<int32_t>(i)) != refused.end();
      EXPECT_EQ(flip.steps[i].chord, bad.steps[i].chord);
      EXPECT_EQ(flip.steps[i].side, was_refused ? 1 - bad.steps[i].side : bad.steps[i].side);
      EXPECT_EQ(flip.steps[i].concave, bad.steps[i].concave && !was_refused);
      if (!was_refused) EXPECT_EQ(flip.steps[i].side_quads, bad.steps[i].side_quads);
      hexes += (flip.steps[i].concave ? -1 : 1) * static_cast<int64_t>(flip.steps[i].side_quads.size());
    }
    EXPECT_EQ(flip.stats.predicted_hexes, hexes);
    EXPECT_EQ(flip.stats.concave_steps, concave_steps(bad) - flipped);
    EXPECT_EQ(flip.final_quads, bad.final_quads);  // the same chords went: the same cube

    ReconstructionResult rec = run_reconstruction(p.surface, flip, {}, {}, &state);
    ASSERT_TRUE(rec.status.ok()) << rec.status.message;
    EXPECT_LT(rec.stats.invalid_intrusion_steps.size(), refused.size());
    if (rec.stats.invalid_intrusion_steps.empty())
      EXPECT_EQ(static_cast<int64_t>(rec.complex.hexes.size()), flip.stats.predicted_hexes);
  }
}
