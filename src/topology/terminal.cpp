// Terminal fill of a stuck surface by digging a pit (see terminal.h).
//
// Pit under a disc F of the stuck surface S (outward quads): every vertex w of F gets a copy w'
// a little inside; P = S without F, plus F's quads on the copies (same corner order, so still
// outward: they face the pit's mouth), plus for every rim edge a->b of F (in F's orientation) the
// wall quad (a, b, b', a'). The layer hexes (f' below, f above: bottom = f' in VTK order) glue
// onto P's complex (pillowed whole first, see pillow_whole) along F' and the walls and leave S
// as the boundary. Discs are ranked by how
// many edges of P join two vertices of valence 3 (each blocks the chord across it), fewest first,
// then by the discs' sorted quad ids.
#include "hexpeel/terminal.h"

#include "hexpeel/chords.h"
#include "hexpeel/reconstruction.h"
#include "quality/quality_internal.h"

#include <algorithm>
#include <chrono>
#include <map>
#include <set>
#include <tuple>

namespace hexpeel {
namespace {

/// S's quads by corner: for each half-edge 4q+k, the quad across it.
std::vector<int32_t> across(const QuadSurface& s) {
  const QuadAdjacency adj = build_adjacency(s);
  std::vector<int32_t> out(adj.opposite.size(), -1);
  for (size_t he = 0; he < adj.opposite.size(); ++he)
    if (adj.opposite[he] >= 0) out[he] = adj.opposite[he] >> 2;
  return out;
}

/// Whether the sorted quad set F is a disc: edge-connected, its rim one simple loop.
bool is_disc(const QuadSurface& s, const std::vector<int32_t>& nb, const std::vector<int32_t>& f) {
  auto in_f = [&](int32_t q) { return std::binary_search(f.begin(), f.end(), q); };
  std::vector<int32_t> stack{f[0]}, seen{f[0]};
  while (!stack.empty()) {
    const int32_t q = stack.back();
    stack.pop_back();
    for (int k = 0; k < 4; ++k) {
      const int32_t r = nb[4 * q + k];
      if (r >= 0 && in_f(r) && std::find(seen.begin(), seen.end(), r) == seen.end()) {
        seen.push_back(r);
        stack.push_back(r);
      }
    }
  }
  if (seen.size() != f.size()) return false;
  std::map<int32_t, int32_t> next;  // rim: a -> b for every rim edge a->b
  for (int32_t q : f)
    for (int k = 0; k < 4; ++k)
      if (!in_f(nb[4 * q + k]))
        if (!next.emplace(s.quads[q][k], s.quads[q][(k + 1) & 3]).second) return false;
  if (next.empty()) return false;
  size_t n = 0;
  int32_t a = next.begin()->first;
  const int32_t a0 = a;
  do {
    auto it = next.find(a);
    if (it == next.end() || ++n > next.size()) return false;
    a = it->second;
  } while (a != a0);
  return n == next.size();
}

/// The pit surface of S under F: P's points, quads, and for each P vertex the S vertex it is
/// (>= 0) or copies (-1 - w).
struct Pit {
  QuadSurface surface;
  std::vector<int32_t> origin;
  std::vector<int32_t> disc;
  int32_t blocking = 0;  ///< edges of P between two valence-3 vertices
};

Pit dig(const QuadSurface& s, const std::vector<int32_t>& nb, const std::vector<int32_t>& f) {
  auto in_f = [&](int32_t q) { return std::binary_search(f.begin(), f.end(), q); };
  const int32_t ns = s.num_points();
  std::vector<int32_t> rim(ns, 0), in_disc(ns, 0);
  std::vector<Vec3> normal(ns, Vec3::Zero());
  double edge = 0.0;
  for (int32_t q : f)
    for (int k = 0; k < 4; ++k) {
      const int32_t v = s.quads[q][k];
      in_disc[v] = 1;
      normal[v] += quad_normal(s, q);
      edge += (s.points[s.quads[q][(k + 1) & 3]] - s.points[v]).norm() / (4.0 * f.size());
      if (!in_f(nb[4 * q + k])) rim[v] = rim[s.quads[q][(k + 1) & 3]] = 1;
    }
  Pit p;
  p.disc = f;
  std::vector<int32_t> keep(ns, -1), copy(ns, -1);
  for (int32_t v = 0; v < ns; ++v)
    if (!in_disc[v] || rim[v]) {
      keep[v] = p.surface.num_points();
      p.surface.points.push_back(s.points[v]);
      p.origin.push_back(v);
    }
  for (int32_t v = 0; v < ns; ++v)
    if (in_disc[v]) {
      copy[v] = p.surface.num_points();
      const double l = normal[v].norm();
      p.surface.points.push_back(s.points[v] - (l > 0 ? 0.3 * edge / l : 0.0) * normal[v]);
      p.origin.push_back(-1 - v);
    }
  for (int32_t q = 0; q < s.num_quads(); ++q) {
    const Quad& t = s.quads[q];
    if (!in_f(q)) {
      p.surface.quads.push_back({keep[t[0]], keep[t[1]], keep[t[2]], keep[t[3]]});
      continue;
    }
    p.surface.quads.push_back({copy[t[0]], copy[t[1]], copy[t[2]], copy[t[3]]});
    for (int k = 0; k < 4; ++k)
      if (!in_f(nb[4 * q + k])) {
        const int32_t a = t[k], b = t[(k + 1) & 3];
        p.surface.quads.push_back({keep[a], keep[b], copy[b], copy[a]});
      }
  }
  // On a closed manifold surface a vertex has as many edges as quads; every edge lies in two
  // quads, so each blocking edge is seen twice.
  std::vector<int32_t> valence(p.surface.num_points(), 0);
  for (const Quad& t : p.surface.quads)
    for (int32_t v : t) ++valence[v];
  for (const Quad& t : p.surface.quads)
    for (int k = 0; k < 4; ++k) p.blocking += valence[t[k]] == 3 && valence[t[(k + 1) & 3]] == 3;
  p.blocking /= 2;
  return p;
}

/// Pillows the whole of `k` (the pit surface's complex): every boundary vertex gets a copy that
/// the hexes move onto, and every boundary face a hex between it and its copy (Mitchell &
/// Tautges' pillow with all of k as the shrink set). The boundary stays. Gluing the pit layer
/// onto k directly fails whenever a hex of k has a face that spans two edges of a layer hex at
/// a rim vertex (at a corner of the disc, a hex holding both of the corner's walls): the union
/// is then pinched there, which pillowing that hex alone does not undo. After the whole pillow,
/// the only hexes at the pit's vertices are pillow hexes, each on one face of P, and the layer
/// meets k exactly in the floor and the walls.
void pillow_whole(HexComplex& k) {
  std::map<std::array<int32_t, 4>, int32_t> uses;  // sorted face -> hexes using it
  auto key = [&](const Hex& h, const std::array<int, 4>& lf) {
    std::array<int32_t, 4> f{h[lf[0]], h[lf[1]], h[lf[2]], h[lf[3]]};
    std::sort(f.begin(), f.end());
    return f;
  };
  for (const Hex& h : k.hexes)
    for (const auto& lf : kHexFaces) ++uses[key(h, lf)];
  std::vector<int32_t> copy(k.num_vertices, -1);
  for (int32_t v = 0; v < static_cast<int32_t>(copy.size()); ++v)
    if (k.input_vertex[v] >= 0) {
      copy[v] = k.num_vertices++;
      k.input_vertex.push_back(-1);
      k.created_at.push_back(-1);
    }
  const size_t n = k.hexes.size();
  for (size_t i = 0; i < n; ++i) {
    const Hex old = k.hexes[i];
    for (const auto& lf : kHexFaces)  // faces seen from outside the hex
      if (uses[key(old, lf)] == 1) {
        Hex p;
        for (int j = 0; j < 4; ++j) {
          p[j] = copy[old[lf[j]]];
          p[j + 4] = old[lf[j]];
        }
        k.hexes.push_back(p);
      }
    for (int32_t& v : k.hexes[i])
      if (copy[v] >= 0) v = copy[v];
  }
}

struct Candidate {
  int32_t blocking = 0;       ///< Pit::blocking of its pit
  std::vector<int32_t> disc;  ///< sorted quad ids
};

/// Discs tried on S, best first: edge-connected sets of 2 or 3 quads and the stars of vertices
/// (a single quad's pit always gives 4 copies of valence 3 joined in a ring, so it is left out).
std::vector<Candidate> candidate_pits(const QuadSurface& s, const std::vector<int32_t>& nb) {
  std::set<std::vector<int32_t>> discs;
  for (int32_t q = 0; q < s.num_quads(); ++q)
    for (int k = 0; k < 4; ++k) {
      const int32_t r = nb[4 * q + k];
      if (r < 0 || r == q) continue;
      discs.insert({std::min(q, r), std::max(q, r)});
      for (int32_t x : {q, r})
        for (int j = 0; j < 4; ++j) {
          const int32_t t = nb[4 * x + j];
          if (t < 0 || t == q || t == r) continue;
          std::vector<int32_t> tri{q, r, t};
          std::sort(tri.begin(), tri.end());
          discs.insert(tri);
        }
    }
  std::vector<std::vector<int32_t>> star(s.num_points());
  for (int32_t q = 0; q < s.num_quads(); ++q)
    for (int32_t v : s.quads[q]) star[v].push_back(q);
  for (auto& st : star) {
    std::sort(st.begin(), st.end());
    st.erase(std::unique(st.begin(), st.end()), st.end());
    if (st.size() > 1) discs.insert(st);
  }
  // Only the rank is kept: the pit surfaces are dug again when tried, so that a fill that
  // succeeds early never holds thousands of them.
  std::vector<Candidate> out;
  for (const std::vector<int32_t>& f : discs)
    if (f.size() + 2 <= static_cast<size_t>(s.num_quads()) && is_disc(s, nb, f))
      out.push_back({dig(s, nb, f).blocking, f});
  std::sort(out.begin(), out.end(), [](const Candidate& a, const Candidate& b) {
    return std::tie(a.blocking, a.disc) < std::tie(b.blocking, b.disc);
  });
  return out;
}

/// What is left of the fill's budget: pits to try and planning work (budget seconds).
struct Budget {
  int32_t tries = 0;
  double effort = 0.0;
  bool left() const { return tries > 0 && effort > 0; }
};

/// A hex complex of `s` (vertices: s's first, in its numbering, then interior ones) by a pit
/// and the planning of the pit surface, or an empty fill.
struct Fill {
  TerminalFill fill;  ///< faces per quad of s, vertices 0..s.num_points()-1 are s's
  int32_t pits = 0, pit_quads = 0;
};

bool fill_surface(const QuadSurface& s, const TerminalParams& params, const PlannerParams& planner,
                  int depth, Budget& budget, Fill& out);

/// Plans and reconstructs the pit surface; on success its complex with the layer, in s's
/// numbering. When the pit surface gets stuck, `stuck_quads` is the size of the surface it
/// stopped at, and with `nest` (and depth > 1) that surface is filled in turn.
bool fill_with_pit(const QuadSurface& s, const Pit& pit, const TerminalParams& params,
                   const PlannerParams& planner, int depth, bool nest, Budget& budget, Fill& out,
                   int32_t& stuck_quads) {
  const QuadSurface& ps = pit.surface;
  const QuadAdjacency adj = build_adjacency(ps);
  for (int32_t o : adj.opposite)
    if (o < 0) return false;
  const ChordSet chords = find_chords(ps, adj);
  for (const Chord& c : chords.chords)
    if (c.self_intersecting) return false;
  const EdgeGeometry edges = classify_edges(ps, adj, params.sharp_angle_deg);
  EliminationState state(ps, chords, edges);
  PlannerParams pp = planner;
  pp.budget_s = std::min(params.budget_s, budget.effort);
  pp.improve_budget_s = std::min(pp.improve_budget_s, 0.2 * pp.budget_s);
  PlannerResult pr = run_planner(state, pp);
  // The digging, chord and edge set-up of a try count too (about 1 us per quad), so that tens
  // of thousands of tries of large pit surfaces stay within the budget.
  budget.effort -= pr.stats.effort_s + 1e-6 * ps.num_quads();
  int32_t nested_pits = 0;
  stuck_quads = pr.plan.status.code == StatusCode::stuck ? state.alive_quads() : -1;
  if (stuck_quads >= 0 && nest && depth > 1 && budget.left()) {
    std::vector<int32_t> ids;
    const QuadSurface inner = state.current_surface(&ids);
    Fill nested;
    if (inner.num_quads() > params.max_quads ||
        !fill_surface(inner, params, planner, depth - 1, budget, nested))
      return false;
    // The nested fill is in `inner`'s numbering, its faces in inner's quad order (= ids).
    pr.plan.final_quads = ids;
    pr.plan.final_corners.clear();
    for (int32_t q : ids) pr.plan.final_corners.push_back(state.corners(q));
    pr.plan.terminal = std::move(nested.fill);
    pr.plan.status = Status::success();
    nested_pits = nested.pits;
  }
  if (!pr.plan.status.ok()) return false;
  ReconstructionParams rp;
  ReconstructionResult rec = run_reconstruction(ps, pr.plan, rp, {}, &state);
  if (!rec.status.ok()) return false;
  HexComplex& k = rec.complex;
  pillow_whole(k);
  // Complex vertices: s's vertices first (those on P from P's complex, F's inner ones new), then
  // P's complex's interior vertices.
  const int32_t ns = s.num_points();
  std::vector<int32_t> of_pc(k.num_vertices, -1);  // -> fill vertex (s's vertices keep theirs)
  std::vector<int32_t> pc_of_p(ps.num_points(), -1);
  for (int32_t v = 0; v < k.num_vertices; ++v)
    if (k.input_vertex[v] >= 0) pc_of_p[k.input_vertex[v]] = v;
  for (int32_t pv = 0; pv < ps.num_points(); ++pv)
    if (pit.origin[pv] >= 0) of_pc[pc_of_p[pv]] = pit.origin[pv];
  int32_t next = ns;
  for (int32_t v = 0; v < k.num_vertices; ++v)
    if (of_pc[v] < 0) of_pc[v] = next++;
  TerminalFill& t = out.fill;
  t = {};
  t.num_vertices = next;
  for (const Hex& h : k.hexes) {
    Hex m;
    for (int i = 0; i < 8; ++i) m[i] = of_pc[h[i]];
    t.hexes.push_back(m);
  }
  std::vector<int32_t> copy_of(ns, -1);  // s vertex -> fill vertex of its copy
  for (int32_t pv = 0; pv < ps.num_points(); ++pv)
    if (pit.origin[pv] < 0) copy_of[-1 - pit.origin[pv]] = of_pc[pc_of_p[pv]];
  for (int32_t q : pit.disc) {
    const Quad& f = s.quads[q];
    Hex h;
    for (int i = 0; i < 4; ++i) {
      h[i] = copy_of[f[i]];
      h[i + 4] = f[i];
    }
    t.hexes.push_back(h);
  }
  for (const Quad& f : s.quads) t.faces.push_back(f);  // s's vertices keep their numbers
  // Any defect left: no ball, so try the next pit.
  if (!quality_detail::is_ball(t.num_vertices, t.hexes)) return false;
  out.pits = 1 + nested_pits;
  out.pit_quads = static_cast<int32_t>(pit.disc.size());
  return true;
}

bool fill_surface(const QuadSurface& s, const TerminalParams& params, const PlannerParams& planner,
                  int depth, Budget& budget, Fill& out) {
  const std::vector<int32_t> nb = across(s);
  for (int32_t x : nb)
    if (x < 0) return false;
  // Every pit first on its own; then, deeper, the pits whose surfaces got furthest (stopped at
  // the fewest quads, fewer than s has) have the surfaces they stopped at filled in turn,
  // furthest first. One pit rarely unblocks every chord of a large stuck surface, but it often
  // lets elimination go on to a smaller one.
  const std::vector<Candidate> cands = candidate_pits(s, nb);
  auto attempt = [&](size_t i, bool nest, int32_t& stuck_quads) {
    --budget.tries;
    return fill_with_pit(s, dig(s, nb, cands[i].disc), params, planner, depth, nest, budget, out,
                         stuck_quads);
  };
  std::vector<std::pair<int32_t, size_t>> progress;  // (stuck quads, candidate)
  for (size_t i = 0; i < cands.size(); ++i) {
    if (!budget.left()) return false;
    int32_t stuck_quads = -1;
    if (attempt(i, false, stuck_quads)) return true;
    if (stuck_quads >= 0 && stuck_quads < s.num_quads()) progress.emplace_back(stuck_quads, i);
  }
  if (depth <= 1) return false;
  std::sort(progress.begin(), progress.end());
  if (progress.size() > static_cast<size_t>(params.descend)) progress.resize(params.descend);
  for (const auto& [stuck_quads, i] : progress) {
    if (!budget.left()) return false;
    int32_t again = -1;
    if (attempt(i, true, again)) return true;
  }
  return false;
}

}  // namespace

TerminalStats fill_stuck_surface(const EliminationState& state, EliminationPlan& plan,
                                 const TerminalParams& params, const PlannerParams& planner,
                                 const Context& ctx) {
  const auto t0 = std::chrono::steady_clock::now();
  TerminalStats st;
  std::vector<int32_t> ids;
  const QuadSurface s = state.current_surface(&ids);
  st.stuck_quads = s.num_quads();
  if (!params.enabled || plan.status.code != StatusCode::stuck || s.num_quads() > params.max_quads)
    return st;
  st.tried = true;
  Budget budget{std::max(1, params.max_tries), params.total_budget_s};
  Fill fill;
  ctx.report("stuck fill", 0.0);
  st.filled = fill_surface(s, params, planner, std::max(1, params.depth), budget, fill);
  st.tries = std::max(1, params.max_tries) - budget.tries;
  st.effort_s = params.total_budget_s - budget.effort;
  if (st.filled) {
    // The fill is in s's numbering, its faces in s's quad order (= ids); the plan's corners
    // name merged input vertices.
    plan.final_quads = ids;
    plan.final_corners.clear();
    for (int32_t q : ids) plan.final_corners.push_back(state.corners(q));
    plan.terminal = std::move(fill.fill);
    plan.status = Status::success();
    st.pits = fill.pits;
    st.pit_quads = fill.pit_quads;
    st.hexes = static_cast<int32_t>(plan.terminal.hexes.size());
    plan.stats.predicted_hexes += st.hexes - 1;  // the fill instead of the cube's one hex
  }
  ctx.report("stuck fill", 1.0);
  st.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return st;
}

}  // namespace hexpeel
