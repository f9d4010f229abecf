// Tests of the terminal fill (terminal.h): a surface on which no chord can be eliminated gets a
// hex complex through a pit, the plan completes, reconstruction gives a ball whose boundary is
// the surface, and the planner ends at once on such a surface (its root is dead).
#include "hexpeel/pipeline.h"
#include "hexpeel/planner.h"
#include "hexpeel/reconstruction.h"
#include "hexpeel/terminal.h"
#include "quality/quality_internal.h"
#include "support/prepared.h"

#include <gtest/gtest.h>

#include <algorithm>

using namespace hexpeel;

namespace {

/// 20 quads, 22 vertices, 6 chords, none of which can be eliminated (collapsing any would leave
/// a vertex of valence 2 or an edge with other than two quads): the surface a real surface's
/// elimination stopped at (a genus-0 cut of a published hex mesh), with its vertices moved onto
/// the unit sphere.
QuadSurface stuck_surface() {
  QuadSurface s;
  s.points = {
      {0.169790, -0.252678, -0.952536},
      {0.182906, -0.254652, -0.949578},
      {0.180238, -0.254812, -0.950045},
      {0.167865, -0.252946, -0.952806},
      {0.137879, -0.248284, -0.958825},
      {0.107763, -0.243377, -0.963927},
      {0.106042, -0.242530, -0.964331},
      {0.137990, -0.247738, -0.958950},
      {0.138097, -0.247204, -0.959072},
      {0.107981, -0.242298, -0.964174},
      {0.095258, -0.241281, -0.965769},
      {0.092775, -0.240303, -0.966254},
      {0.095475, -0.240204, -0.966016},
      {0.137986, -0.247750, -0.958947},
      {0.106038, -0.242543, -0.964328},
      {0.107760, -0.243384, -0.963925},
      {0.107978, -0.242306, -0.964173},
      {0.167864, -0.252954, -0.952804},
      {0.169787, -0.252691, -0.952533},
      {0.168085, -0.251865, -0.953054},
      {0.180457, -0.253730, -0.950293},
      {0.168083, -0.251873, -0.953052}};
  s.quads = {{0, 1, 2, 3}, {4, 5, 6, 7}, {8, 7, 6, 9}, {6, 5, 10, 11}, {9, 6, 11, 12}, {4, 13, 14, 15}, {15, 10, 5, 4}, {16, 14, 13, 8}, {9, 12, 16, 8}, {12, 11, 14, 16}, {14, 11, 10, 15}, {4, 3, 2, 17}, {18, 13, 4, 17}, {0, 19, 20, 1}, {8, 13, 18, 21}, {19, 8, 21, 20}, {17, 2, 1, 18}, {21, 18, 1, 20}, {7, 0, 3, 4}, {19, 0, 7, 8}};
  return s;
}

TEST(Terminal, PlannerEndsAtADeadRoot) {
  hexpeel::testing::Prepared p = hexpeel::testing::prepare(stuck_surface());
  EliminationState state(p.surface, p.chords, p.edges);
  PlannerResult pr = run_planner(state);
  EXPECT_EQ(pr.plan.status.code, StatusCode::stuck);
  EXPECT_TRUE(pr.plan.steps.empty());
  EXPECT_FALSE(pr.stats.budget_exhausted);  // proven: no chord can go, nothing else to search
  EXPECT_NE(pr.plan.status.message.find("every order tried got stuck"), std::string::npos);
}

TEST(Terminal, StuckSurfaceIsFilledThroughAPit) {
  hexpeel::testing::Prepared p = hexpeel::testing::prepare(stuck_surface());
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

// Through the pipeline: a mesh that is a ball with the surface as its boundary (its hexes are
// not all positive on this small, folded shape: the figures are the pipeline's business), and
// without the fill the run fails as stuck.
TEST(Terminal, PipelineMeshesAStuckSurface) {
  const PolygonSoup soup = to_polygon_soup(stuck_surface());
  MeshParams mp;
  mp.alternatives = 0;
  MeshResult r = run_mesh(soup, mp);
  ASSERT_TRUE(r.status.ok()) << to_string(r.status);
  EXPECT_TRUE(r.terminal.filled);
  EXPECT_TRUE(r.quality.is_ball) << r.quality.topology_message;
  EXPECT_EQ(r.quality.boundary_matches_surface, true) << r.quality.boundary_message;
  EXPECT_TRUE(to_json(r).contains("stuck_fill"));
  mp.terminal.enabled = false;
  MeshResult off = run_mesh(soup, mp);
  EXPECT_EQ(off.status.code, StatusCode::stuck);
  EXPECT_FALSE(off.terminal.tried);
}

}  // namespace
