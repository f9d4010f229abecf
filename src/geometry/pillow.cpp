// Forced configurations and pillowing of a shrink set (Mitchell & Tautges, "Pillowing doublets:
// refining a mesh to ensure that faces share at most one edge", IMR 1995).
//
// A corner tetrahedron whose 4 points are boundary vertices keeps the Jacobian the surface gives
// it; when that is <= forced_sj no placement helps (DESIGN.md "Geometry"). Pillowing a set S of
// hexes: every vertex on the boundary of S (the faces of S's hexes not shared with another S hex)
// gets a new interior copy, S's hexes use the copies, and each boundary face (a,b,c,d) of S (seen
// from outside S) gets the hex (a',b',c',d', a,b,c,d). Faces of S on the surface stay surface
// faces (now of the new hexes), so the surface is unchanged vertex for vertex; the vertices of S's
// faces are the only ones copied. If S is a ball (or several disjoint balls) the result is a ball;
// this is checked and a pillow that fails the check is not used.
//
// Shrink set: the forced hexes grown by `grow` rings of face neighbours (local), or every hex
// (whole boundary) when local pillowing cannot be used or leaves more forced corners. Hexes at a
// boundary vertex whose quads leave no strictly inward direction are kept out of S: no copy of
// such a vertex can make all its pillow hexes positive.
#include "hexpeel/pillow.h"
#include "quality/quality_internal.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>

namespace hexpeel {

std::string_view to_string(PillowMode m) {
  switch (m) {
    case PillowMode::none: return "none";
    case PillowMode::automatic: return "auto";
    case PillowMode::all: return "all";
  }
  return "?";
}

std::string_view to_string(ForcedKind k) {
  switch (k) {
    case ForcedKind::flat_doublet: return "flat_doublet";
    case ForcedKind::concave_corner: return "concave_corner";
    case ForcedKind::fixed_corner: return "fixed_corner";
    case ForcedKind::collinear: return "collinear";
  }
  return "?";
}

/// The direction maximizing min_i (-d . n_i) over unit d is the centre of the smallest spherical
/// cap holding every -n_i, and that cap is fixed by at most 3 of them: it is -n_i, the bisector of
/// some -n_i, -n_j, or a point equidistant from some three. Trying all of those (valences are
/// small) makes the test exact, where the mean normal alone misses skewed stars.
bool has_inward_direction(const std::vector<Vec3>& unit_normals, double margin) {
  const auto& ns = unit_normals;
  if (ns.empty()) return true;
  auto inward = [&](Vec3 d) {
    const double l = d.norm();
    if (!(l > 1e-12)) return false;
    d /= l;
    for (const Vec3& n : ns)
      if (d.dot(n) > -margin) return false;
    return true;
  };
  Vec3 mean = Vec3::Zero();
  for (const Vec3& n : ns) mean += n;
  if (inward(-mean)) return true;
  const size_t m = ns.size();
  for (size_t i = 0; i < m; ++i) {
    if (inward(-ns[i])) return true;
    for (size_t j = i + 1; j < m; ++j) {
      if (inward(-(ns[i] + ns[j]))) return true;
      for (size_t k = j + 1; k < m; ++k) {
        const Vec3 c = (ns[j] - ns[i]).cross(ns[k] - ns[i]);  // equidistant from the three
        if (inward(c) || inward(-c)) return true;
      }
    }
  }
  return false;
}

namespace {

using FaceKey = std::array<int32_t, 4>;

FaceKey face_key(const Hex& h, int lf) {
  FaceKey k;
  for (int i = 0; i < 4; ++i) k[i] = h[kHexFaces[lf][i]];
  std::sort(k.begin(), k.end());
  return k;
}

/// For each slot 6*hex + local face: the slot of the other hex on that face, -1 on the boundary.
std::vector<int32_t> face_neighbours(const std::vector<Hex>& hexes) {
  const int32_t ns = 6 * static_cast<int32_t>(hexes.size());
  std::vector<std::pair<FaceKey, int32_t>> faces(ns);
  for (int32_t s = 0; s < ns; ++s) faces[s] = {face_key(hexes[s / 6], s % 6), s};
  std::sort(faces.begin(), faces.end());
  std::vector<int32_t> nb(ns, -1);
  for (int32_t i = 0; i + 1 < ns; ++i)
    if (faces[i].first == faces[i + 1].first) {
      nb[faces[i].second] = faces[i + 1].second;
      nb[faces[i + 1].second] = faces[i].second;
    }
  return nb;
}

/// Boundary vertices (complex ids) whose surface quads admit no strictly inward direction d
/// (d . n < -1e-3 for every unit quad-corner normal n at the vertex): see has_inward_direction.
std::vector<uint8_t> no_inward_direction(const QuadSurface& surface, const HexComplex& complex) {
  std::vector<std::vector<Vec3>> normals(surface.num_points());
  for (const Quad& q : surface.quads)
    for (int k = 0; k < 4; ++k) {
      const Vec3& p = surface.points[q[k]];
      Vec3 n = (surface.points[q[(k + 1) % 4]] - p).cross(surface.points[q[(k + 3) % 4]] - p);
      const double l = n.norm();
      if (l > 0) normals[q[k]].push_back(n / l);
    }
  std::vector<uint8_t> bad_input(surface.num_points(), 0);
  for (int32_t v = 0; v < surface.num_points(); ++v)
    bad_input[v] = !normals[v].empty() && !has_inward_direction(normals[v], 1e-3);
  std::vector<uint8_t> bad(complex.num_vertices, 0);
  for (int32_t v = 0; v < complex.num_vertices; ++v)
    if (complex.input_vertex[v] >= 0) bad[v] = bad_input[complex.input_vertex[v]];
  return bad;
}

/// The complex with S (in_s[h] != 0) pillowed.
HexComplex pillow_set(const HexComplex& c, const std::vector<uint8_t>& in_s,
                      const std::vector<int32_t>& nb, int32_t* new_hexes, int32_t* new_vertices) {
  HexComplex out = c;
  std::vector<int32_t> copy(c.num_vertices, -1);
  std::vector<int32_t> faces;  // slots of S's boundary faces, in slot order
  for (int32_t s = 0; s < 6 * static_cast<int32_t>(c.hexes.size()); ++s)
    if (in_s[s / 6] && (nb[s] < 0 || !in_s[nb[s] / 6])) faces.push_back(s);
  const int32_t depth = c.created_at.empty()
                            ? 0
                            : *std::max_element(c.created_at.begin(), c.created_at.end()) + 1;
  for (int32_t s : faces)
    for (int i = 0; i < 4; ++i) {
      const int32_t v = c.hexes[s / 6][kHexFaces[s % 6][i]];
      if (copy[v] < 0) {
        copy[v] = out.num_vertices++;
        out.input_vertex.push_back(-1);
        out.created_at.push_back(depth);
      }
    }
  for (size_t h = 0; h < c.hexes.size(); ++h)
    if (in_s[h])
      for (int32_t& v : out.hexes[h])
        if (copy[v] >= 0) v = copy[v];
  for (int32_t s : faces) {
    const Hex& h = c.hexes[s / 6];
    Hex n;
    for (int i = 0; i < 4; ++i) {
      const int32_t v = h[kHexFaces[s % 6][i]];
      n[i] = copy[v];
      n[i + 4] = v;
    }
    out.hexes.push_back(n);
  }
  *new_hexes = static_cast<int32_t>(faces.size());
  *new_vertices = out.num_vertices - c.num_vertices;
  return out;
}

bool is_ball(const HexComplex& c) {
  HexMesh m;
  m.points.assign(c.num_vertices, Vec3::Zero());
  m.hexes = c.hexes;
  return quality_detail::analyze_topology(m).is_ball;
}

}  // namespace

std::vector<ForcedConfiguration> find_forced_configurations(const QuadSurface& surface,
                                                            const HexComplex& complex,
                                                            double forced_sj) {
  std::vector<ForcedConfiguration> out;
  const std::vector<int32_t> nb = face_neighbours(complex.hexes);
  auto fixed = [&](int32_t v) { return complex.input_vertex[v] >= 0; };
  auto pos = [&](int32_t v) -> const Vec3& { return surface.points[complex.input_vertex[v]]; };
  for (int32_t h = 0; h < static_cast<int32_t>(complex.hexes.size()); ++h) {
    const Hex& hex = complex.hexes[h];
    for (int c = 0; c < 8; ++c) {
      const std::array<int32_t, 4> k{hex[c], hex[kHexCornerFrames[c][0]],
                                     hex[kHexCornerFrames[c][1]], hex[kHexCornerFrames[c][2]]};
      std::array<int32_t, 4> fx{};
      int nfix = 0;
      for (int32_t v : k)
        if (fixed(v)) fx[nfix++] = v;
      if (nfix == 3) {
        const Vec3 a = pos(fx[1]) - pos(fx[0]), b = pos(fx[2]) - pos(fx[0]);
        if (a.cross(b).norm() <= 1e-9 * a.norm() * b.norm())
          out.push_back({h, c, ForcedKind::collinear, 0.0});
        continue;
      }
      if (nfix < 4) continue;
      const Vec3 e0 = pos(k[1]) - pos(k[0]), e1 = pos(k[2]) - pos(k[0]), e2 = pos(k[3]) - pos(k[0]);
      const double l = e0.norm() * e1.norm() * e2.norm();
      const double sj = l > 0 ? e0.dot(e1.cross(e2)) / l : -1.0;
      if (sj > forced_sj) continue;
      int boundary_faces = 0;  // boundary faces of this hex that contain the corner
      for (int lf = 0; lf < 6; ++lf) {
        if (nb[6 * h + lf] >= 0) continue;
        for (int i = 0; i < 4; ++i)
          if (kHexFaces[lf][i] == c) ++boundary_faces;
      }
      const ForcedKind kind = boundary_faces >= 3   ? ForcedKind::concave_corner
                              : boundary_faces == 2 ? ForcedKind::flat_doublet
                                                    : ForcedKind::fixed_corner;
      out.push_back({h, c, kind, sj});
    }
  }
  return out;
}

PillowResult run_pillow(const QuadSurface& surface, const HexComplex& complex,
                        const PillowParams& params, const Context& ctx) {
  const auto t0 = std::chrono::steady_clock::now();
  PillowResult res;
  res.complex = complex;
  res.forced = find_forced_configurations(surface, complex, params.forced_sj);
  PillowStats& st = res.stats;
  st.forced = static_cast<int32_t>(res.forced.size());
  for (const ForcedConfiguration& f : res.forced) {
    if (f.kind == ForcedKind::flat_doublet) ++st.flat_doublets;
    if (f.kind == ForcedKind::concave_corner) ++st.concave_corners;
    if (f.kind == ForcedKind::fixed_corner) ++st.fixed_corners;
    if (f.kind == ForcedKind::collinear) ++st.collinear;
  }
  st.forced_after = st.forced;
  const bool want = params.mode == PillowMode::all ||
                    (params.mode == PillowMode::automatic && st.forced > 0);
  if (!want || complex.hexes.empty()) {
    st.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return res;
  }
  const int32_t nh = static_cast<int32_t>(complex.hexes.size());
  const std::vector<int32_t> nb = face_neighbours(complex.hexes);
  const std::vector<uint8_t> bad = no_inward_direction(surface, complex);
  st.excluded_vertices = static_cast<int32_t>(std::count(bad.begin(), bad.end(), 1));
  std::vector<uint8_t> allowed(nh, 1);
  for (int32_t h = 0; h < nh; ++h)
    for (int32_t v : complex.hexes[h])
      if (bad[v]) allowed[h] = 0;

  struct Candidate {
    HexComplex complex;
    int32_t set_size = 0, new_hexes = 0, new_vertices = 0, forced_after = 0;
    bool whole = false;
  };
  auto attempt = [&](const std::vector<uint8_t>& in_s, bool whole, Candidate* out) {
    Candidate c;
    c.whole = whole;
    c.set_size = static_cast<int32_t>(std::count(in_s.begin(), in_s.end(), 1));
    if (c.set_size == 0) return false;
    c.complex = pillow_set(complex, in_s, nb, &c.new_hexes, &c.new_vertices);
    if (!is_ball(c.complex)) return false;
    c.forced_after =
        static_cast<int32_t>(find_forced_configurations(surface, c.complex, params.forced_sj).size());
    *out = std::move(c);
    return true;
  };

  Candidate best;
  bool have = false;
  if (params.mode == PillowMode::automatic) {
    std::vector<uint8_t> in_s(nh, 0);
    for (const ForcedConfiguration& f : res.forced)
      if (allowed[f.hex]) in_s[f.hex] = 1;
    for (int ring = 0; ring < params.grow; ++ring) {
      std::vector<uint8_t> next = in_s;
      for (int32_t s = 0; s < 6 * nh; ++s)
        if (in_s[s / 6] && nb[s] >= 0 && allowed[nb[s] / 6]) next[nb[s] / 6] = 1;
      in_s.swap(next);
    }
    int32_t touching = 0;  // hexes with a vertex on the boundary
    for (const Hex& h : complex.hexes)
      for (int32_t v : h)
        if (complex.input_vertex[v] >= 0) {
          ++touching;
          break;
        }
    const int32_t set_size = static_cast<int32_t>(std::count(in_s.begin(), in_s.end(), 1));
    if (params.whole_fraction >= 1.0 || set_size < params.whole_fraction * touching)
      have = attempt(in_s, false, &best);
    ctx.report("pillow", 0.5);
  }
  if (!have || best.forced_after > 0) {
    Candidate whole;
    bool ok = attempt(allowed, true, &whole);
    if (!ok) ok = attempt(std::vector<uint8_t>(nh, 1), true, &whole);
    if (ok && (!have || whole.forced_after < best.forced_after)) {
      best = std::move(whole);
      have = true;
    }
  }
  if (have) {
    res.complex = std::move(best.complex);
    st.shrink_set = best.set_size;
    st.new_hexes = best.new_hexes;
    st.new_vertices = best.new_vertices;
    st.forced_after = best.forced_after;
    st.whole_boundary = best.whole;
  } else {
    ctx.warn("pillow: no shrink set gave a ball complex; the mesh is not pillowed");
  }
  ctx.report("pillow", 1.0);
  st.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

}  // namespace hexpeel
