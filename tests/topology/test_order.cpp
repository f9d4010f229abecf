// Tests of the order rules (order.h; Kremer et al. 2013 sections 4-5) and of reconstruction by
// intrusion (5.3): every rule changes the greedy order on a surface built for it, quick keys are
// lower bounds of full keys, intrusion gives a ball whose boundary is the input, an impossible
// intrusion is reported as invalid_intrusion with no mesh, and kremer vs original on voxel solids.
#include "hexpeel/chords.h"
#include "hexpeel/elimination.h"
#include "hexpeel/order.h"
#include "hexpeel/pipeline.h"
#include "hexpeel/quality.h"
#include "hexpeel/reconstruction.h"
#include "support/generators.h"
#include "support/prepared.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <functional>
#include <string>
#include <tuple>
#include <vector>

using namespace hexpeel;
namespace ht = hexpeel::testing;

namespace {

using ht::Prepared;
using ht::prepare;

/// The greedy plan's steps as (chord, side, concave) triples.
using Signature = std::vector<std::tuple<int32_t, int, bool>>;

Signature plan_of(const Prepared& p, const OrderParams& order, EliminationPlan* out = nullptr) {
  EliminationState st(p.surface, p.chords, p.edges);
  EliminationParams ep;
  ep.order = order;
  EliminationPlan plan = run_elimination(st, ep);
  Signature sig;
  for (const PlanStep& s : plan.steps) sig.emplace_back(s.chord, s.side, s.concave);
  if (out) *out = std::move(plan);
  return sig;
}

/// Greedy (no search), simple placement: what the order rules and the reconstruction do.
MeshParams greedy_params(const OrderParams& order) {
  MeshParams mp;
  mp.elimination.order = order;
  mp.search = false;
  mp.reconstruction.verify_each_step = true;
  mp.pillow.mode = PillowMode::none;
  mp.untangle.untangle = mp.untangle.optimize = false;
  mp.alternatives = 0;  // these tests are about the given order
  mp.intrusion_flip_rounds = 0;  // ... and its plan
  return mp;
}

OrderParams kremer() { return OrderParams{}; }

/// True when switching `rule` off changes the greedy order on `g`.
bool rule_matters(const ht::Generated& g, const std::function<void(OrderParams&)>& off,
                  const std::function<void(OrderParams&)>& base = {}) {
  Prepared p = prepare(g.surface);
  OrderParams on = kremer();
  if (base) base(on);
  OrderParams o = on;
  off(o);
  return plan_of(p, on) != plan_of(p, o);
}

}  // namespace

TEST(Order, KremerIsTheDefaultAndOriginalStaysSelectable) {
  EXPECT_EQ(OrderParams{}.method, Method::kremer);
  EXPECT_EQ(to_string(Method::original), "original");
  Prepared p = prepare(ht::cube(3, 3, 3).surface);
  OrderParams o;
  o.method = Method::original;
  EliminationPlan plan;
  plan_of(p, o, &plan);
  ASSERT_TRUE(plan.status.ok());
  EXPECT_EQ(plan.stats.concave_steps, 0);
}

TEST(Order, QuickKeyIsALowerBoundOfFullKey) {
  for (const ht::Generated& g : {ht::named_solid("pocket", 1), ht::named_solid("steps", 1),
                                 ht::named_solid("U", 2), ht::random_voxel_solid(3, 4, 10)}) {
    Prepared p = prepare(g.surface);
    EliminationState st(p.surface, p.chords, p.edges);
    const OrderPolicy policy(kremer());
    // Walk the greedy plan, checking every feasible chord at every state.
    EliminationParams ep;
    EliminationState walk(p.surface, p.chords, p.edges);
    EliminationPlan plan = run_elimination(walk, ep);
    for (size_t i = 0; i <= plan.steps.size(); ++i) {
      for (int32_t c = 0; c < st.num_chords(); ++c) {
        if (!st.chord_alive(c)) continue;
        auto f = st.feasibility(c);
        if (!f.ok()) continue;
        Move q = policy.quick(st, c), m = policy.full(st, c, f.sides);
        EXPECT_LE(q.key, m.key) << g.name << " step " << i << " chord " << c;
        EXPECT_TRUE(m.side == 0 || m.side == 1);
        EXPECT_TRUE(f.sides[m.side]) << g.name << " chord " << c << " got an unusable side";
      }
      if (i < plan.steps.size()) st.apply(plan.steps[i].chord, plan.steps[i].side);
    }
  }
}

TEST(Order, ConcaveRuleEliminatesThePocketRimFirst) {
  // pocket3x3x2: the ring of 4 pocket walls has concavity 1 towards the floor (one quad).
  Prepared p = prepare(ht::named_solid("pocket", 1).surface);
  EliminationPlan plan;
  plan_of(p, kremer(), &plan);
  ASSERT_TRUE(plan.status.ok()) << plan.status.message;
  ASSERT_FALSE(plan.steps.empty());
  EXPECT_TRUE(plan.steps[0].concave);
  EXPECT_EQ(plan.steps[0].side_quads.size(), 1u);
  EXPECT_EQ(plan.steps[0].chord_quads.size(), 4u);
  EXPECT_EQ(plan.stats.concave_steps, 1);
  EXPECT_EQ(plan.stats.predicted_hexes, 17);
  OrderParams off = kremer();
  off.concave = false;
  EliminationPlan plain;
  plan_of(p, off, &plain);
  EXPECT_EQ(plain.stats.concave_steps, 0);
  EXPECT_FALSE(plain.steps.empty() || plain.steps[0].chord == plan.steps[0].chord);
}

TEST(Order, ZeroVolumeRuleChangesTheOrder) {
  // pocket3x3x2 without concave chords: the chords over the one-quad pocket floor cross two
  // concave edges in a row (outside angles 90 + 90 = 180 degrees).
  auto no_concave = [](OrderParams& o) { o.concave = false; };
  EXPECT_TRUE(rule_matters(ht::named_solid("pocket", 1), [](OrderParams& o) { o.zero_volume = false; },
                           no_concave));
}

TEST(Order, EnclosedRuleChangesTheOrder) {
  // A random 9-voxel solid where the heavier side of some chord holds a whole chord.
  EXPECT_TRUE(rule_matters(ht::random_voxel_solid(3, 4, 9), [](OrderParams& o) { o.enclosed = false; }));
}

TEST(Order, FalsePositiveRuleChangesTheOrder) {
  // With every concave edge counting (concave_min tiny), sides that hold sharp edges are false
  // positives; without the rule they are eliminated as concave.
  auto loose = [](OrderParams& o) { o.concave_min = 1e-6; };
  EXPECT_TRUE(rule_matters(ht::named_solid("L", 2), [](OrderParams& o) { o.false_positive = false; },
                           loose));
}

TEST(Order, ConcaveWaitsForEnclosedRuleChangesTheOrder) {
  // pocket at m=2 with loose concavity: the upper wall ring is concave towards the floor only
  // once the lower ring (non-flat, enclosed on that side) is gone.
  auto loose = [](OrderParams& o) { o.concave_min = 1e-6; o.false_positive = false; };
  EXPECT_TRUE(rule_matters(ht::named_solid("pocket", 2),
                           [](OrderParams& o) { o.concave_waits_for_enclosed = false; }, loose));
}

TEST(Reconstruction, IntrusionGivesABallWithTheInputBoundary) {
  for (int m = 1; m <= 2; ++m) {
    ht::Generated g = ht::named_solid("pocket", m);
    MeshResult r = run_mesh(to_polygon_soup(g.surface), greedy_params(kremer()));
    ASSERT_TRUE(r.status.ok()) << g.name << ": " << to_string(r.status);
    EXPECT_GT(r.plan.stats.concave_steps, 0) << g.name;
    EXPECT_EQ(r.reconstruction.intrusions, r.plan.stats.concave_steps) << g.name;
    EXPECT_GT(r.reconstruction.steps_verified, 0) << g.name;
    EXPECT_EQ(r.mesh.num_hexes(), 17 * m * m * m) << g.name;  // the voxel grid itself
    QualityReport q = run_quality(r.mesh, {}, &g.surface);
    EXPECT_TRUE(q.is_ball) << g.name << ": " << q.topology_message;
    EXPECT_EQ(q.boundary_matches_surface, true) << g.name << ": " << q.boundary_message;
    EXPECT_EQ(q.euler_characteristic, 1);
    // No orphan points: every point is a hex corner.
    std::vector<uint8_t> used(r.mesh.points.size(), 0);
    for (const Hex& h : r.mesh.hexes)
      for (int32_t v : h) used[v] = 1;
    for (size_t v = 0; v < used.size(); ++v) EXPECT_TRUE(used[v]) << g.name << " point " << v;
    EXPECT_EQ(q.sj_count_nonpositive, 0) << g.name;
  }
}

/// Every concave edge counting and no 5.4 safeguards: greedy, with intrusions that cannot be
/// done refused (no fallback to extrusion).
MeshParams loose_strict_params() {
  OrderParams loose = kremer();
  loose.concave_min = 1e-6;
  loose.false_positive = false;
  loose.concave_waits_for_enclosed = false;
  MeshParams strict = greedy_params(loose);
  strict.reconstruction.fallback_to_extrusion = false;
  return strict;
}

TEST(Reconstruction, InvalidIntrusionIsReportedWithNoMesh) {
  // With every concave edge counting and no 5.4 safeguards, a one-voxel-thick U gets a concave
  // step whose side faces have no hex beneath: the intrusion must fail cleanly.
  int reported = 0;
  for (const char* shape : {"U", "L", "T", "stairs", "steps"}) {
    ht::Generated g = ht::named_solid(shape, 2);
    const MeshParams strict = loose_strict_params();
    MeshResult r = run_mesh(to_polygon_soup(g.surface), strict);
    if (r.status.code != StatusCode::invalid_intrusion) {
      EXPECT_TRUE(r.status.ok() || r.status.code == StatusCode::stuck) << g.name << ": " << to_string(r.status);
      continue;
    }
    ++reported;
    EXPECT_TRUE(r.mesh.hexes.empty()) << g.name;
    EXPECT_NE(r.status.message.find("concave step"), std::string::npos) << r.status.message;
    EXPECT_FALSE(r.reconstruction.invalid_intrusion_steps.empty());
    // The same plan with the fallback: the step is extruded, the mesh is valid.
    MeshParams fb = loose_strict_params();
    fb.reconstruction.fallback_to_extrusion = true;
    MeshResult f = run_mesh(to_polygon_soup(g.surface), fb);
    ASSERT_TRUE(f.status.ok()) << g.name << ": " << to_string(f.status);
    EXPECT_FALSE(f.reconstruction.invalid_intrusion_steps.empty());
    QualityReport q = run_quality(f.mesh, {}, &g.surface);
    EXPECT_TRUE(q.is_ball && q.boundary_matches_surface == true) << g.name;
  }
  EXPECT_GT(reported, 0);
}

// The pipeline's fallback: when the given order's intrusion is refused, other orders are tried
// and the first that meshes is kept (no untangling here, so a valid result ends the search).
TEST(Reconstruction, OtherOrdersGetPastARefusedIntrusion) {
  int rescued = 0;
  for (const char* shape : {"U", "L", "T", "stairs", "steps"}) {
    ht::Generated g = ht::named_solid(shape, 2);
    MeshParams strict = loose_strict_params();
    strict.alternatives = 3;
    MeshResult r = run_mesh(to_polygon_soup(g.surface), strict);
    ASSERT_FALSE(r.tries.empty()) << g.name;
    if (r.tries[0].status != StatusCode::invalid_intrusion) continue;
    ASSERT_TRUE(r.status.ok()) << g.name << ": " << to_string(r.status);
    ++rescued;
    EXPECT_GT(r.kept_try, 0);
    EXPECT_EQ(r.tries.size(), static_cast<size_t>(r.kept_try) + 1);  // stops at the first valid
    EXPECT_EQ(r.tries.back().status, StatusCode::ok);
    QualityReport q = run_quality(r.mesh, {}, &g.surface);
    EXPECT_TRUE(q.is_ball && q.boundary_matches_surface == true) << g.name;
  }
  EXPECT_GT(rescued, 0);
}

// When the given order's reconstruction extrudes a concave step whose intrusion it refused, the
// other side rule is tried as well (not the original method, which has no concave steps) and
// the better mesh kept; with no refusal, or with --alternatives 0, nothing else is tried.
TEST(Reconstruction, RefusedIntrusionTriesTheOtherSideRule) {
  int refused = 0, clean = 0;
  for (const char* shape : {"U", "L", "T", "stairs", "steps"}) {
    ht::Generated g = ht::named_solid(shape, 2);
    MeshParams one = loose_strict_params();
    one.reconstruction.fallback_to_extrusion = true;  // extrude refused steps (the default)
    const MeshResult first = run_mesh(to_polygon_soup(g.surface), one);
    ASSERT_TRUE(first.status.ok()) << g.name << ": " << to_string(first.status);
    ASSERT_EQ(first.tries.size(), 1u);
    MeshParams more = one;
    more.alternatives = 3;
    const MeshResult r = run_mesh(to_polygon_soup(g.surface), more);
    ASSERT_TRUE(r.status.ok()) << g.name << ": " << to_string(r.status);
    if (first.reconstruction.invalid_intrusion_steps.empty()) {
      ++clean;
      EXPECT_EQ(r.tries.size(), 1u) << g.name;
      continue;
    }
    ++refused;
    ASSERT_EQ(r.tries.size(), 2u) << g.name;
    EXPECT_EQ(r.tries[1].method, Method::kremer);
    EXPECT_NE(r.tries[1].side_rule, r.tries[0].side_rule);
    // Built unless its plan predicts over 1.5 times the first's hexes.
    if (r.tries[1].skipped_plan_hexes > 0) {
      EXPECT_GT(r.tries[1].skipped_plan_hexes, 1.5 * first.plan.stats.predicted_hexes) << g.name;
      EXPECT_EQ(r.kept_try, 0) << g.name;
      EXPECT_TRUE(to_json(r)["orders_tried"][1]["hexes"].is_null()) << g.name;
    } else {
      EXPECT_GT(r.tries[1].hexes, 0) << g.name;
    }
    EXPECT_GE(r.quality.sj_min, first.quality.sj_min) << g.name;
    QualityReport q = run_quality(r.mesh, {}, &g.surface);
    EXPECT_TRUE(q.is_ball && q.boundary_matches_surface == true) << g.name;
  }
  EXPECT_GT(refused, 0);
}

TEST(Order, KremerOnVoxelSolidsMeshesWhatOriginalMeshes) {
  std::vector<ht::Generated> gs;
  for (const char* shape : {"L", "U", "T", "pocket", "notch", "stairs", "steps"})
    for (int m = 1; m <= 2; ++m) gs.push_back(ht::named_solid(shape, m));
  for (uint64_t seed = 1; seed <= 8; ++seed) gs.push_back(ht::random_voxel_solid(seed, 4, 6 + static_cast<int>(seed)));
  OrderParams orig;
  orig.method = Method::original;
  MeshParams kp = greedy_params(kremer());  // invalid intrusions fall back to extrusion
  int ok[2] = {0, 0}, good[2] = {0, 0};
  int64_t singular[2] = {0, 0};
  for (const ht::Generated& g : gs) {
    MeshResult a = run_mesh(to_polygon_soup(g.surface), greedy_params(orig));
    MeshResult b = run_mesh(to_polygon_soup(g.surface), kp);
    ok[0] += a.status.ok(), ok[1] += b.status.ok();
    if (a.status.ok()) {
      good[0] += a.quality.sj_count_nonpositive == 0;
      EXPECT_TRUE(b.status.ok()) << g.name << ": kremer failed where original meshed: " << to_string(b.status);
    }
    if (b.status.ok()) good[1] += b.quality.sj_count_nonpositive == 0;
    if (a.status.ok() && b.status.ok()) {
      singular[0] += a.quality.singular_edges_interior;
      singular[1] += b.quality.singular_edges_interior;
    }
  }
  std::printf("voxel solids: original %d meshed (%d all positive, %lld interior singular edges); "
              "kremer %d meshed (%d all positive, %lld)\n",
              ok[0], good[0], static_cast<long long>(singular[0]), ok[1], good[1],
              static_cast<long long>(singular[1]));
  EXPECT_GE(ok[1], ok[0]);
  EXPECT_GE(good[1], good[0]);
  EXPECT_LE(singular[1], singular[0]);
}

