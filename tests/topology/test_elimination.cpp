// Tests of the elimination engine: the local polyhedrality test against a brute-force
// 3-connectivity check, undo restoring the state exactly, and greedy runs reaching the cube.
#include "hexpeel/chords.h"
#include "hexpeel/elimination.h"
#include "support/generators.h"
#include "support/prepared.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>

using namespace hexpeel;
namespace ht = hexpeel::testing;

namespace {

using ht::Prepared;
using ht::prepare;

/// Ground truth for one collapse: apply it globally on a copy of the current surface and test
/// that the result is a polyhedral sphere: proper quads, every edge in two quads, one fan per
/// vertex, Euler characteristic 2, and a 3-vertex-connected edge graph (brute force).
bool brute_force_polyhedral(const EliminationState& st, int32_t chord) {
  std::vector<int32_t> ids;
  QuadSurface cur = st.current_surface(&ids);
  std::map<int32_t, int32_t> slot;
  for (size_t i = 0; i < ids.size(); ++i) slot[ids[i]] = static_cast<int32_t>(i);
  std::vector<ChordStep> steps;
  st.chord_steps(chord, steps);
  std::vector<int32_t> par(cur.num_points());
  for (int32_t i = 0; i < cur.num_points(); ++i) par[i] = i;
  auto find = [&](int32_t v) {
    while (par[v] != v) v = par[v];
    return v;
  };
  std::set<int32_t> removed;
  for (const ChordStep& s : steps) {
    int32_t q = slot.at(s.quad);
    removed.insert(q);
    int32_t a = find(cur.quads[q][s.edge]), b = find(cur.quads[q][(s.edge + 1) & 3]);
    if (a != b) par[std::max(a, b)] = std::min(a, b);
  }
  std::vector<Quad> faces;
  for (int32_t q = 0; q < cur.num_quads(); ++q) {
    if (removed.count(q)) continue;
    Quad t;
    for (int k = 0; k < 4; ++k) t[k] = find(cur.quads[q][k]);
    std::set<int32_t> distinct(t.begin(), t.end());
    if (distinct.size() != 4) return false;
    faces.push_back(t);
  }
  std::map<std::pair<int32_t, int32_t>, int> ecount;
  std::map<int32_t, std::set<int32_t>> adj;
  for (const Quad& t : faces)
    for (int k = 0; k < 4; ++k) {
      int32_t a = t[k], b = t[(k + 1) & 3];
      ++ecount[{std::min(a, b), std::max(a, b)}];
      adj[a].insert(b);
      adj[b].insert(a);
    }
  for (auto& [e, n] : ecount)
    if (n != 2) return false;
  // one fan per vertex: faces around v connected through edges at v
  for (auto& [v, nb] : adj) {
    std::vector<int> at;
    for (size_t f = 0; f < faces.size(); ++f)
      if (std::find(faces[f].begin(), faces[f].end(), v) != faces[f].end()) at.push_back(static_cast<int>(f));
    std::vector<int> comp(at.size());
    for (size_t i = 0; i < at.size(); ++i) comp[i] = static_cast<int>(i);
    auto cf = [&](int x) { while (comp[x] != x) x = comp[x]; return x; };
    for (size_t i = 0; i < at.size(); ++i)
      for (size_t j = i + 1; j < at.size(); ++j) {
        int shared_edge = 0;
        const Quad& a = faces[at[i]];
        const Quad& b = faces[at[j]];
        for (int k = 0; k < 4; ++k)
          for (int l = 0; l < 4; ++l)
            if (a[k] == v && b[l] == v &&
                (a[(k + 1) & 3] == b[(l + 3) & 3] || a[(k + 3) & 3] == b[(l + 1) & 3]))
              shared_edge = 1;
        if (shared_edge) comp[cf(static_cast<int>(i))] = cf(static_cast<int>(j));
      }
    std::set<int> roots;
    for (size_t i = 0; i < at.size(); ++i) roots.insert(cf(static_cast<int>(i)));
    if (roots.size() != 1) return false;
  }
  int64_t chi = static_cast<int64_t>(adj.size()) - static_cast<int64_t>(ecount.size()) +
                static_cast<int64_t>(faces.size());
  if (chi != 2) return false;
  std::vector<int32_t> nodes;
  for (auto& [v, nb] : adj) nodes.push_back(v);
  if (nodes.size() < 4) return false;
  auto connected_without = [&](int32_t x, int32_t y) {
    std::set<int32_t> seen;
    std::vector<int32_t> stack;
    for (int32_t v : nodes)
      if (v != x && v != y) {
        stack.push_back(v);
        seen.insert(v);
        break;
      }
    while (!stack.empty()) {
      int32_t v = stack.back();
      stack.pop_back();
      for (int32_t u : adj[v])
        if (u != x && u != y && seen.insert(u).second) stack.push_back(u);
    }
    size_t expect = nodes.size() - (x == y ? 1 : 2);
    return seen.size() == expect;
  };
  for (size_t i = 0; i < nodes.size(); ++i)
    for (size_t j = i; j < nodes.size(); ++j)
      if (!connected_without(nodes[i], nodes[j])) return false;
  return true;
}

std::vector<ht::Generated> small_surfaces() {
  std::vector<ht::Generated> out{ht::cube(2, 2, 2), ht::cube(2, 3, 2), ht::cube(3, 2, 1),
                                 ht::cubed_sphere(3), ht::named_solid("L"), ht::named_solid("U"),
                                 ht::named_solid("stairs")};
  for (uint64_t seed = 1; seed <= 6; ++seed) out.push_back(ht::random_voxel_solid(seed, 3, 6));
  return out;
}

}  // namespace

TEST(Elimination, LocalTestAgreesWithBruteForce3Connectivity) {
  int compared = 0, disagreements = 0, feasible = 0;
  for (const auto& g : small_surfaces()) {
    ASSERT_GT(g.surface.num_quads(), 0) << g.name;
    Prepared p = prepare(g.surface);
    for (uint64_t seed = 0; seed < 4; ++seed) {
      EliminationState st(p.surface, p.chords, p.edges);
      std::mt19937_64 rng(seed);
      while (st.alive_chords() > 3) {
        std::vector<std::pair<int32_t, int>> moves;
        for (int32_t c = 0; c < st.num_chords(); ++c) {
          if (!st.chord_alive(c)) continue;
          bool local = st.collapse_check(c) == Infeasible::none;
          bool brute = brute_force_polyhedral(st, c);
          ++compared;
          feasible += local;
          if (local != brute) {
            ++disagreements;
            ADD_FAILURE() << g.name << " seed " << seed << " step " << st.steps_applied()
                          << " chord " << c << ": local " << local << " brute " << brute;
          }
          auto f = st.feasibility(c);
          // feasibility() adds side checks and shortcuts (low valence) to the local test: a
          // feasible verdict must be polyhedral, a low-valence verdict must not be
          if (f.ok() && !brute) ++disagreements, ADD_FAILURE() << g.name << " chord " << c << ": feasible, not polyhedral";
          if (f.why == Infeasible::low_valence && brute)
            ++disagreements, ADD_FAILURE() << g.name << " chord " << c << ": low valence, but polyhedral";
          if (f.ok())
            for (int s = 0; s < 2; ++s)
              if (f.sides[s]) moves.push_back({c, s});
        }
        if (moves.empty()) break;
        auto [c, s] = moves[rng() % moves.size()];
        st.apply(c, s);
      }
    }
  }
  std::printf("local vs brute-force 3-connectivity: %d collapses compared, %d feasible, %d disagree\n",
              compared, feasible, disagreements);
  EXPECT_GT(compared, 500);
  EXPECT_GT(feasible, 100);
  EXPECT_EQ(disagreements, 0);
}

TEST(Elimination, UndoRestoresTheSurfaceExactly) {
  ht::Generated g = ht::named_solid("notch", 2);
  Prepared p = prepare(g.surface);
  EliminationState st(p.surface, p.chords, p.edges);
  std::mt19937_64 rng(7);
  std::vector<std::vector<Quad>> history;
  auto snapshot = [&] {
    std::vector<Quad> out;
    for (int32_t q = 0; q < p.surface.num_quads(); ++q)
      out.push_back(st.quad_alive(q) ? st.corners(q) : Quad{-1, -1, -1, -1});
    return out;
  };
  std::vector<std::vector<ChordWeights>> weights;
  auto all_weights = [&] {
    std::vector<ChordWeights> w;
    for (int32_t c = 0; c < st.num_chords(); ++c) w.push_back(st.weights(c));
    return w;
  };
  // Corner ids after undo may be other representatives of the same merged class only if the
  // union-find were restored incorrectly; compare exactly.
  while (st.alive_chords() > 3) {
    std::vector<std::pair<int32_t, int>> moves;
    for (int32_t c = 0; c < st.num_chords(); ++c) {
      if (!st.chord_alive(c)) continue;
      auto f = st.feasibility(c);
      if (f.ok())
        for (int s = 0; s < 2; ++s)
          if (f.sides[s]) moves.push_back({c, s});
    }
    if (moves.empty()) break;
    history.push_back(snapshot());
    weights.push_back(all_weights());
    auto [c, s] = moves[rng() % moves.size()];
    st.apply(c, s);
  }
  ASSERT_GT(history.size(), 5u);
  while (!history.empty()) {
    st.undo();
    EXPECT_EQ(snapshot(), history.back());
    auto w = all_weights();
    for (size_t c = 0; c < w.size(); ++c) {
      EXPECT_EQ(w[c].length, weights.back()[c].length);
      EXPECT_EQ(w[c].sharp, weights.back()[c].sharp);
      EXPECT_EQ(w[c].crossing_sharp, weights.back()[c].crossing_sharp);
    }
    history.pop_back();
    weights.pop_back();
  }
  EXPECT_EQ(st.alive_quads(), p.surface.num_quads());
  EXPECT_EQ(st.alive_chords(), static_cast<int32_t>(p.chords.chords.size()));
}

TEST(Elimination, CubeGridReachesTheCubeWithOnePlanStepPerChord) {
  for (int n = 2; n <= 5; ++n) {
    ht::Generated g = ht::cube(n, n, n);
    Prepared p = prepare(g.surface);
    EliminationState st(p.surface, p.chords, p.edges);
    EliminationPlan plan = run_elimination(st);
    ASSERT_TRUE(plan.status.ok()) << to_string(plan.status);
    EXPECT_EQ(plan.steps.size(), static_cast<size_t>(3 * n - 3));
    EXPECT_EQ(plan.final_quads.size(), 6u);
    EXPECT_EQ(plan.stats.predicted_hexes, static_cast<int64_t>(n) * n * n) << "n = " << n;
    EXPECT_EQ(st.alive_quads(), 6);
  }
}

TEST(Elimination, FluxSideSizesEqualSearchedRegions) {
  int compared = 0;
  for (const auto& g : small_surfaces()) {
    Prepared p = prepare(g.surface);
    EliminationState st(p.surface, p.chords, p.edges);
    std::mt19937_64 rng(11);
    std::vector<int32_t> region;
    while (st.alive_chords() > 3) {
      std::vector<std::pair<int32_t, int>> moves;
      for (int32_t c = 0; c < st.num_chords(); ++c) {
        if (!st.chord_alive(c)) continue;
        auto f = st.feasibility(c);
        for (int s = 0; s < 2; ++s) {
          if (!f.sides[s]) continue;  // usable sides are edge-connected
          st.side_region(c, s, region);
          EXPECT_EQ(st.side_size(c, s), static_cast<int32_t>(region.size()))
              << g.name << " step " << st.steps_applied() << " chord " << c << " side " << s;
          ++compared;
          if (f.ok()) moves.push_back({c, s});
        }
      }
      if (moves.empty()) break;
      auto [c, s] = moves[rng() % moves.size()];
      st.apply(c, s);
    }
  }
  EXPECT_GT(compared, 200);
}

TEST(Elimination, CachedWeightsMatchAFreshState) {
  // weights() is cached per chord and invalidated by collapses and undos; after a random walk
  // of applies and undos it must equal the weights of a fresh state with the same chords gone.
  int compared = 0;
  for (const auto& g : small_surfaces()) {
    Prepared p = prepare(g.surface);
    for (uint64_t seed = 1; seed <= 4; ++seed) {
      EliminationState st(p.surface, p.chords, p.edges);
      std::mt19937_64 rng(seed);
      std::vector<int32_t> path;
      for (int step = 0; step < 60 && st.alive_chords() > 3; ++step) {
        for (int32_t c = 0; c < st.num_chords(); ++c)
          if (st.chord_alive(c)) st.weights(c);  // warm the cache
        if (!path.empty() && rng() % 3 == 0) {
          st.undo();
          path.pop_back();
        } else {
          std::vector<int32_t> feasible;
          for (int32_t c = 0; c < st.num_chords(); ++c)
            if (st.chord_alive(c) && st.feasibility(c).ok()) feasible.push_back(c);
          if (feasible.empty()) break;
          const int32_t c = feasible[rng() % feasible.size()];
          st.collapse(c);
          path.push_back(c);
        }
        EliminationState fresh(p.surface, p.chords, p.edges);
        for (int32_t c : path) fresh.collapse(c);
        for (int32_t c = 0; c < st.num_chords(); ++c) {
          if (!st.chord_alive(c)) continue;
          const ChordWeights a = st.weights(c), b = fresh.weights(c);
          ++compared;
          ASSERT_EQ(a.length, b.length) << g.name << " chord " << c;
          ASSERT_EQ(a.sharp, b.sharp) << g.name << " chord " << c;
          ASSERT_EQ(a.convex, b.convex) << g.name << " chord " << c;
          ASSERT_EQ(a.concave, b.concave) << g.name << " chord " << c;
          ASSERT_EQ(a.crossing_sharp, b.crossing_sharp) << g.name << " chord " << c;
        }
      }
    }
  }
  EXPECT_GT(compared, 1000);
}
