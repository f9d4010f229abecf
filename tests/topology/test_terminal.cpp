// Tests of the terminal fill (terminal.h): a surface on which no chord can be eliminated gets a
// hex complex through a pit, the plan completes, reconstruction gives a ball whose boundary is
// the surface, and the planner ends at once on such a surface (its root is dead).
#include "hexpeel/pipeline.h"
#include "hexpeel/planner.h"
#include "hexpeel/reconstruction.h"
#include "hexpeel/terminal.h"
#include "quality/quality_internal.h"
#include "support/generators.h"
#include "support/prepared.h"

#include <gtest/gtest.h>

#include <algorithm>

using namespace hexpeel;

namespace {

TEST(Terminal, PlannerEndsAtADeadRoot) {
  hexpeel::testing::Prepared p = hexpeel::testing::prepare(hexpeel::testing::stuck_surface());
  EliminationState state(p.surface, p.chords, p.edges);
  PlannerResult pr = run_planner(state);
  EXPECT_EQ(pr.plan.status.code, StatusCode::stuck);
  EXPECT_TRUE(pr.plan.steps.empty());
  EXPECT_FALSE(pr.stats.budget_exhausted);  // proven: no chord can go, nothing else to search
  EXPECT_NE(pr.plan.status.message.find("every order tried got stuck"), std::string::npos);
}

TEST(Terminal, StuckSurfaceIsFilledThroughAPit) {
  hexpeel::testing::Prepared p = hexpeel::testing::prepare(hexpeel::testing::stuck_surface());
  EliminationState state(p.surface, p.chords, p.edges);
  PlannerResult pr = run_planner(state);
  ASSERT_EQ(pr.plan.status.code, StatusCode::stuck);
  EliminationPlan plan = pr.plan;
  TerminalStats st = fill_stuck_surface(state, plan, {}, {});
  ASSERT_TRUE(st.filled);
  EXPECT_TRUE(st.tried);
  EXPECT_EQ(st.stuck_quads, 20);
  EXPECT_GE(st.pits, 1);
  EXPECT_GE(st.pit_quads, 2);
  EXPECT_GT(st.tries, 0);
  ASSERT_TRUE(plan.status.ok());
  EXPECT_EQ(plan.final_quads.size(), 20u);
  EXPECT_EQ(static_cast<int32_t>(plan.terminal.hexes.size()), st.hexes);
  // Reconstruction starts from the fill and checks the boundary against the surface.
  ReconstructionResult rec = run_reconstruction(p.surface, plan, {}, {}, &state);
  ASSERT_TRUE(rec.status.ok()) << to_string(rec.status);
  EXPECT_EQ(rec.stats.hexes, st.hexes);
  HexMesh m;
  m.points.assign(rec.complex.num_vertices, Vec3::Zero());
  m.hexes = rec.complex.hexes;
  const auto topo = quality_detail::analyze_topology(m);
  EXPECT_TRUE(topo.is_ball) << topo.message;
  for (int32_t v = 0; v < p.surface.num_points(); ++v) {
    const auto it = std::find(rec.complex.input_vertex.begin(), rec.complex.input_vertex.end(), v);
    EXPECT_NE(it, rec.complex.input_vertex.end()) << "surface vertex " << v;
  }
  // The same fill again: deterministic.
  EliminationState again(p.surface, p.chords, p.edges);
  EliminationPlan plan2 = run_planner(again).plan;
  fill_stuck_surface(again, plan2, {}, {});
  EXPECT_EQ(plan2.terminal.hexes, plan.terminal.hexes);
}

// Through the pipeline: a mesh that is a ball with the surface as its boundary and no inverted
// hex (40 hexes, min scaled Jacobian 0.337 when written), and without the fill the run fails as
// stuck.
TEST(Terminal, PipelineMeshesAStuckSurface) {
  const PolygonSoup soup = to_polygon_soup(hexpeel::testing::stuck_surface());
  MeshParams mp;
  mp.alternatives = 0;
  MeshResult r = run_mesh(soup, mp);
  ASSERT_TRUE(r.status.ok()) << to_string(r.status);
  EXPECT_TRUE(r.terminal.filled);
  EXPECT_TRUE(r.quality.is_ball) << r.quality.topology_message;
  EXPECT_EQ(r.quality.boundary_matches_surface, true) << r.quality.boundary_message;
  EXPECT_EQ(r.quality.sj_count_nonpositive, 0);
  EXPECT_GT(r.quality.sj_min, 0.1);
  EXPECT_TRUE(to_json(r).contains("stuck_fill"));
  mp.terminal.enabled = false;
  MeshResult off = run_mesh(soup, mp);
  EXPECT_EQ(off.status.code, StatusCode::stuck);
  EXPECT_FALSE(off.terminal.tried);
}

}  // namespace
