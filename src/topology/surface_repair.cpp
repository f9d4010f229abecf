// Surface repair by refinement: every quad into four or six (surface_repair.h).
#include "hexpeel/surface_repair.h"

#include "hexpeel/chords.h"

#include <algorithm>
#include <string>

namespace hexpeel {
namespace {

/// The point of quad q's bilinear patch at (u, v): corner 0 at (0,0), 1 at (1,0), 2 at (1,1).
Vec3 bilinear(const QuadSurface& s, const Quad& q, double u, double v) {
  return (1 - u) * (1 - v) * s.points[q[0]] + u * (1 - v) * s.points[q[1]] +
         u * v * s.points[q[2]] + (1 - u) * v * s.points[q[3]];
}

}  // namespace

int six_split_diagonal(const QuadSurface& surface, int32_t q) {
  const Quad& f = surface.quads[q];
  const Vec3* p = surface.points.data();
  return (p[f[0]] - p[f[2]]).squaredNorm() <= (p[f[1]] - p[f[3]]).squaredNorm() ? 0 : 1;
}

QuadSurface refine_surface(const QuadSurface& surface, const std::vector<char>& six,
                           std::vector<int32_t>& parent) {
  const QuadAdjacency adj = build_adjacency(surface);
  QuadSurface out;
  out.points = surface.points;
  out.quads.reserve(6 * surface.quads.size());
  parent.clear();
  parent.reserve(6 * surface.quads.size());
  // midpoint[he]: the vertex halving half-edge he (made by the first of its two quads)
  std::vector<int32_t> midpoint(4 * surface.quads.size(), -1);
  auto mid = [&](int32_t q, int k) {
    const int32_t he = 4 * q + k;
    if (midpoint[he] < 0) {
      const Quad& f = surface.quads[q];
      midpoint[he] = out.num_points();
      out.points.push_back(0.5 * (surface.points[f[k]] + surface.points[f[(k + 1) % 4]]));
      if (adj.opposite[he] >= 0) midpoint[adj.opposite[he]] = midpoint[he];
    }
    return midpoint[he];
  };
  auto add = [&](int32_t q, Quad f) {
    out.quads.push_back(f);
    parent.push_back(q);
  };
  for (int32_t q = 0; q < surface.num_quads(); ++q) {
    const Quad& f = surface.quads[q];
    const int32_t m[4] = {mid(q, 0), mid(q, 1), mid(q, 2), mid(q, 3)};
    const int32_t centre = out.num_points();
    out.points.push_back(bilinear(surface, f, 0.5, 0.5));
    if (!six[q]) {
      for (int k = 0; k < 4; ++k) add(q, {f[k], m[k], centre, m[(k + 3) % 4]});
      continue;
    }
    // Two triangles along the shorter diagonal, r = 0 (0-2) or 1 (1-3); the diagonal's midpoint
    // is the quad's centre. Corners of triangle t in quad order: r+2t, r+2t+1, r+2t+2.
    const int r = six_split_diagonal(surface, q);
    for (int t = 0; t < 2; ++t) {
      const int a = (r + 2 * t) % 4, b = (a + 1) % 4, c = (a + 2) % 4;
      // centroid of the triangle in the patch's (u, v): corners at (0,0) (1,0) (1,1) (0,1)
      static const double uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
      const double u = (uv[a][0] + uv[b][0] + uv[c][0]) / 3, v = (uv[a][1] + uv[b][1] + uv[c][1]) / 3;
      const int32_t g = out.num_points();
      out.points.push_back(bilinear(surface, f, u, v));
      // edges of the triangle: a-b (quad edge a), b-c (quad edge b), c-a (the diagonal)
      add(q, {f[a], m[a], g, centre});
      add(q, {f[b], m[b], g, m[a]});
      add(q, {f[c], centre, g, m[b]});
    }
  }
  return out;
}

SurfaceRepair repair_surface(const QuadSurface& surface, bool six_everywhere) {
  SurfaceRepair rep;
  SurfaceRepairStats& st = rep.stats;
  const int32_t n = surface.num_quads();
  st.input_quads = n;
  st.input_odd = n % 2 != 0;
  const QuadAdjacency adj = build_adjacency(surface);
  const ChordSet in_chords = find_chords(surface, adj);
  std::vector<char> six(n, 0);
  for (const Chord& c : in_chords.chords)
    for (int32_t q : c.crossings) {
      six[q] = 1;
      ++st.input_self_crossings;
    }
  if (six_everywhere) std::fill(six.begin(), six.end(), 1);
  // vertex -> quads, for growing by vertex neighbours
  std::vector<std::vector<int32_t>> around(surface.num_points());
  for (int32_t q = 0; q < n; ++q)
    for (int32_t v : surface.quads[q]) around[v].push_back(q);

  for (;;) {
    ++st.rounds;
    QuadSurface refined = refine_surface(surface, six, rep.parent);
    const ChordSet chords = find_chords(refined, build_adjacency(refined));
    std::vector<int32_t> grow;
    for (const Chord& c : chords.chords)
      for (int32_t q : c.crossings)
        if (!six[rep.parent[q]]) grow.push_back(rep.parent[q]);
    if (chord_stats(chords).self_intersecting == 0) {
      st.output_chords = static_cast<int32_t>(chords.chords.size());
      rep.surface = std::move(refined);
      break;
    }
    if (grow.empty()) {  // every crossing lies in quads split into six: take their neighbours
      for (const Chord& c : chords.chords)
        for (int32_t q : c.crossings)
          for (int32_t v : surface.quads[rep.parent[q]])
            for (int32_t nq : around[v])
              if (!six[nq]) grow.push_back(nq);
    }
    if (grow.empty()) {
      for (const Chord& c : chords.chords)
        if (c.self_intersecting) {
          const int32_t at = c.crossings.front();
          rep.status = Status::error(
              StatusCode::self_intersecting_chord,
              "surface repair: with every quad split into six, a chord still crosses itself at "
              "refined quad " + std::to_string(at) + " (in input quad " +
                  std::to_string(rep.parent[at]) + "); the surface cannot be repaired by refinement");
          break;
        }
      rep.parent.clear();
      return rep;
    }
    for (int32_t q : grow) six[q] = 1;
  }
  for (int32_t q = 0; q < n; ++q)
    if (six[q]) st.six_split.push_back(q);
  st.output_quads = rep.surface.num_quads();
  st.applied = true;
  return rep;
}

nlohmann::json to_json(const SurfaceRepairStats& s) {
  return {{"applied", s.applied},
          {"input_quads", s.input_quads},
          {"input_odd", s.input_odd},
          {"input_self_crossings", s.input_self_crossings},
          {"output_quads", s.output_quads},
          {"quads_changed", s.applied ? s.input_quads : 0},
          {"six_split_count", static_cast<int64_t>(s.six_split.size())},
          {"six_split", s.six_split},
          {"four_split_count", s.applied ? s.input_quads - static_cast<int64_t>(s.six_split.size()) : 0},
          {"rounds", s.rounds},
          {"output_chords", s.output_chords}};
}

}  // namespace hexpeel
