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
// (whole boundary) when local pillowing cannot be used or leaves more forced corners. A boundary
// vertex's copy must lie strictly inside every surface quad at it that S pillows (each becomes the
// bottom of a pillow hex at the copy); at a saddle no direction does that for all its quads, so S
// is fitted to the boundary: hexes at such a vertex leave S until the pillowed quads there have
// an inward direction (fit_to_boundary), the vertex keeps the rest of its hexes.
#include "hexpeel/pillow.h"
#include "quality/quality_internal.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <bit>
#include <chrono>
#include <tuple>

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

/// A surface quad's corner at a boundary vertex: the corner's unit normal (surface orientation)
/// and the hex whose boundary face the quad is.
struct BoundaryCorner {
  Vec3 normal;
  int32_t hex = -1;
};

/// Per complex vertex, the corners of the surface quads at it (empty for interior vertices), in
/// surface quad order.
std::vector<std::vector<BoundaryCorner>> boundary_corners(const QuadSurface& surface,
                                                          const HexComplex& complex,
                                                          const std::vector<int32_t>& nb) {
  std::vector<int32_t> to_complex(surface.num_points(), -1);
  for (int32_t v = 0; v < complex.num_vertices; ++v)
    if (complex.input_vertex[v] >= 0) to_complex[complex.input_vertex[v]] = v;
  std::vector<std::pair<FaceKey, int32_t>> faces;  // boundary faces of the complex -> hex
  for (int32_t s = 0; s < static_cast<int32_t>(nb.size()); ++s)
    if (nb[s] < 0) faces.push_back({face_key(complex.hexes[s / 6], s % 6), s / 6});
  std::sort(faces.begin(), faces.end());
  std::vector<std::vector<BoundaryCorner>> out(complex.num_vertices);
  for (const Quad& q : surface.quads) {
    FaceKey key;
    for (int i = 0; i < 4; ++i) key[i] = to_complex[q[i]];
    std::sort(key.begin(), key.end());
    const auto it = std::lower_bound(faces.begin(), faces.end(), std::make_pair(key, int32_t{-1}));
    if (key[0] < 0 || it == faces.end() || it->first != key) continue;
    for (int k = 0; k < 4; ++k) {
      const Vec3& p = surface.points[q[k]];
      const Vec3 n = (surface.points[q[(k + 1) % 4]] - p).cross(surface.points[q[(k + 3) % 4]] - p);
      const double l = n.norm();
      if (l > 0) out[to_complex[q[k]]].push_back({n / l, it->second});
    }
  }
  return out;
}

/// Margin of the inward-direction test (unit normals): a copy must sit at least this far inside.
constexpr double kInwardMargin = 1e-3;

/// Whether the surface quads at a vertex whose hexes are in S leave a strictly inward direction
/// for the vertex's copy (every such quad becomes the bottom of a pillow hex at the copy).
bool copy_can_serve(const std::vector<BoundaryCorner>& corners, const std::vector<uint8_t>& in_s,
                    std::vector<Vec3>& scratch) {
  scratch.clear();
  for (const BoundaryCorner& c : corners)
    if (in_s[c.hex]) scratch.push_back(c.normal);
  return has_inward_direction(scratch, kInwardMargin);
}

/// Boundary vertices whose copy S (in_s) cannot serve; with S = every hex, the saddles.
int32_t count_unserved(const std::vector<std::vector<BoundaryCorner>>& corners,
                       const std::vector<uint8_t>& in_s) {
  std::vector<Vec3> scratch;
  int32_t n = 0;
  for (const auto& cs : corners) n += !cs.empty() && !copy_can_serve(cs, in_s, scratch);
  return n;
}

/// The best inward margin max_d min_n (-d . n) over the pillowed quads at a vertex, within 1e-3
/// (bisection on has_inward_direction); 1 when no quad there is pillowed.
/// The best margin over the quads at a vertex whose hexes have in_s[hex] == side, within 1e-3.
double side_margin(const std::vector<BoundaryCorner>& corners, const std::vector<uint8_t>& in_s,
                   uint8_t side, std::vector<Vec3>& scratch) {
  scratch.clear();
  for (const BoundaryCorner& c : corners)
    if (in_s[c.hex] == side) scratch.push_back(c.normal);
  if (scratch.empty()) return 1.0;
  double lo = -1.0, hi = 1.0;
  for (int i = 0; i < 11; ++i) {
    const double mid = 0.5 * (lo + hi);
    (has_inward_direction(scratch, mid) ? lo : hi) = mid;
  }
  return lo;
}
double inward_margin(const std::vector<BoundaryCorner>& corners, const std::vector<uint8_t>& in_s,
                     std::vector<Vec3>& scratch) {
  return side_margin(corners, in_s, 1, scratch);
}

/// The smaller of the two margins at a boundary vertex once S is split there: the copy's over
/// the quads of S's hexes, and the one left over the quads of the other hexes (which keep their
/// own edges into the solid; taken as one direction, the cautious case); 1 for an empty side.
double split_margin(const std::vector<BoundaryCorner>& cs, const std::vector<uint8_t>& in_s,
                    std::vector<Vec3>& scratch) {
  return std::min(side_margin(cs, in_s, 1, scratch), side_margin(cs, in_s, 0, scratch));
}

/// Keeps hexes that are not forced out of S at one boundary vertex (corners `cs`) while the split
/// margin there (split_margin) is below `target`: the fewest such hexes whose removal reaches the
/// target (the largest margin among those, then the lowest ids), or when no set reaches it, the
/// set giving the largest margin (the fewest hexes among those within 1e-3 of it) if that beats
/// the present margin. The sets are enumerated (a vertex has a handful of hexes; with more than
/// kMaxMarginCandidates candidates nothing is tried). Returns the hexes removed.
constexpr int kMaxMarginCandidates = 10;
int32_t raise_margin(std::vector<uint8_t>& in_s, const std::vector<BoundaryCorner>& cs,
                     const std::vector<uint8_t>& forced, double target, std::vector<Vec3>& scratch) {
  if (target <= 0) return 0;  // the copy's margin is > 0 already (copy_can_serve)
  const double margin = split_margin(cs, in_s, scratch);
  if (margin >= target) return 0;
  std::vector<int32_t> cand;
  for (const BoundaryCorner& c : cs)
    if (in_s[c.hex] && !forced[c.hex]) cand.push_back(c.hex);
  std::sort(cand.begin(), cand.end());
  cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
  const int n = static_cast<int>(cand.size());
  if (n == 0 || n > kMaxMarginCandidates) return 0;
  // Subsets in order of size, then of their ids' bit pattern (lowest ids first).
  std::vector<uint32_t> subsets;
  for (uint32_t m = 1; m < (1u << n); ++m) subsets.push_back(m);
  std::stable_sort(subsets.begin(), subsets.end(), [](uint32_t a, uint32_t b) {
    return std::popcount(a) < std::popcount(b);
  });
  uint32_t best = 0, reached = 0;
  double best_margin = margin + 1e-3, reached_margin = target;  // a real gain: exact to 1e-3
  int reached_size = 0;
  for (uint32_t m : subsets) {
    const int size = std::popcount(m);
    if (reached && size > reached_size) break;
    for (int i = 0; i < n; ++i)
      if (m >> i & 1) in_s[cand[i]] = 0;
    const double got = split_margin(cs, in_s, scratch);
    for (int i = 0; i < n; ++i)
      if (m >> i & 1) in_s[cand[i]] = 1;
    if (got >= reached_margin && (!reached || got > reached_margin)) {
      reached = m;
      reached_margin = got;
      reached_size = size;
    }
    if (got > best_margin + 1e-3 || (best == 0 && got > best_margin)) {
      best = m;
      best_margin = got;
    }
  }
  const uint32_t pick = reached ? reached : best;
  for (int i = 0; i < n; ++i)
    if (pick >> i & 1) in_s[cand[i]] = 0;
  return std::popcount(pick);
}

/// Drops hexes from S until every boundary vertex's copy can be served (copy_can_serve). At a
/// vertex that fails, one hex at a time leaves S: a hex that is not forced before one that is, one
/// whose removal alone makes the rest servable first, then the one whose removal leaves the
/// largest inward margin (the most conflicting quad), then the lowest id. Then, where the
/// vertex's margin is below `target_margin` (the pillow hexes' corners at its copy cannot be
/// better than about the margin), hexes that are not forced leave S (raise_margin; a hex kept out
/// of S keeps its corners, so this leaves no forced corner). Dropping only removes normals at other vertices, so one pass over the
/// vertices suffices. Returns the hexes dropped.
int32_t fit_to_boundary(std::vector<uint8_t>& in_s,
                        const std::vector<std::vector<BoundaryCorner>>& corners,
                        const std::vector<uint8_t>& forced, double target_margin) {
  int32_t dropped = 0;
  std::vector<Vec3> scratch;
  for (const std::vector<BoundaryCorner>& cs : corners) {
    while (!cs.empty() && !copy_can_serve(cs, in_s, scratch)) {
      int32_t pick = -1;
      std::tuple<int, int, double, int32_t> pick_key{};
      for (const BoundaryCorner& c : cs) {
        if (!in_s[c.hex]) continue;
        in_s[c.hex] = 0;
        const bool fixes = copy_can_serve(cs, in_s, scratch);
        const double margin = inward_margin(cs, in_s, scratch);
        in_s[c.hex] = 1;
        const std::tuple<int, int, double, int32_t> key{forced[c.hex], !fixes, -margin, c.hex};
        if (pick < 0 || key < pick_key) {
          pick = c.hex;
          pick_key = key;
        }
      }
      in_s[pick] = 0;  // some hex of cs is in S, or the (empty) rest would be servable
      ++dropped;
    }
    if (cs.empty()) continue;
    dropped += raise_margin(in_s, cs, forced, target_margin, scratch);
  }
  return dropped;
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

namespace {

/// One pillowed shrink set.
struct PillowPass {
  HexComplex complex;
  int32_t set_size = 0, new_hexes = 0, new_vertices = 0, forced_after = 0, dropped = 0;
  int32_t unserved = 0;  ///< boundary vertices whose copy has no inward direction
  bool whole = false;
  std::vector<uint8_t> set;  ///< S as pillowed (after the fit to the boundary)
  int32_t defects() const { return forced_after + unserved; }
};

/// Pillows `complex` once around `forced` (its forced configurations): the local shrink set when
/// `local` and it is small enough (any size when not `whole`), else (or when that leaves
/// defects) the whole set when `whole` and it does better; `nb` and `corners` are the complex's
/// face_neighbours and boundary_corners. False when no set gives a ball.
bool pillow_once(const QuadSurface& surface, const HexComplex& complex,
                 const std::vector<int32_t>& nb,
                 const std::vector<std::vector<BoundaryCorner>>& corners,
                 const std::vector<ForcedConfiguration>& forced, const PillowParams& params,
                 bool local, bool whole, PillowPass* out) {
  const int32_t nh = static_cast<int32_t>(complex.hexes.size());
  std::vector<uint8_t> forced_hex(nh, 0);
  for (const ForcedConfiguration& f : forced) forced_hex[f.hex] = 1;

  // Pillows S after fitting it to the boundary (or as given, fit = false: the last resort). When
  // the fit to the target margin leaves no ball, the fit without it (margin 0) is tried.
  auto attempt = [&](const std::vector<uint8_t>& given, bool whole, bool fit, PillowPass* res) {
    const int fits = fit && params.target_margin > 0 ? 2 : 1;
    for (int f = 0; f < fits; ++f) {
      const double margin = f == 0 ? params.target_margin : 0.0;
      std::vector<uint8_t> in_s = given;
      PillowPass c;
      c.whole = whole;
      if (fit) c.dropped = fit_to_boundary(in_s, corners, forced_hex, margin);
      c.set_size = static_cast<int32_t>(std::count(in_s.begin(), in_s.end(), 1));
      if (c.set_size == 0) continue;
      c.complex = pillow_set(complex, in_s, nb, &c.new_hexes, &c.new_vertices);
      if (!quality_detail::is_ball(c.complex.num_vertices, c.complex.hexes)) continue;
      c.forced_after = static_cast<int32_t>(
          find_forced_configurations(surface, c.complex, params.forced_sj).size());
      c.unserved = count_unserved(corners, in_s);
      c.set = std::move(in_s);
      *res = std::move(c);
      return true;
    }
    return false;
  };

  auto grown = [&](std::vector<uint8_t> in_s) {
    for (int ring = 0; ring < params.grow; ++ring) {
      std::vector<uint8_t> next = in_s;
      for (int32_t s = 0; s < 6 * nh; ++s)
        if (in_s[s / 6] && nb[s] >= 0) next[nb[s] / 6] = 1;
      in_s.swap(next);
    }
    return in_s;
  };
  bool have = false;
  if (params.seeds_only) {
    // The repair pillow: the grown seeds together may not be a ball (two of them meeting in an
    // edge), so each seed's grown set joins S only if S stays one that pillows to a ball, in the
    // order given. A seed inside the fitted S so far is served already.
    std::vector<uint8_t> in_s(nh, 0), tried(nh, 0);
    for (const ForcedConfiguration& f : forced) {
      if (tried[f.hex] || (have && out->set[f.hex])) continue;
      tried[f.hex] = 1;
      std::vector<uint8_t> one(nh, 0);
      one[f.hex] = 1;
      std::vector<uint8_t> candidate = grown(std::move(one));
      for (int32_t h = 0; h < nh; ++h) candidate[h] |= in_s[h];
      PillowPass p;
      if (attempt(candidate, false, true, &p)) {
        in_s.swap(candidate);
        *out = std::move(p);
        have = true;
      }
    }
    return have;
  }
  if (local) {
    std::vector<uint8_t> in_s = grown(forced_hex);
    int32_t touching = 0;  // hexes with a vertex on the boundary
    for (const Hex& h : complex.hexes)
      for (int32_t v : h)
        if (complex.input_vertex[v] >= 0) {
          ++touching;
          break;
        }
    const int32_t set_size = static_cast<int32_t>(std::count(in_s.begin(), in_s.end(), 1));
    if (!whole || params.whole_fraction >= 1.0 || set_size < params.whole_fraction * touching)
      have = attempt(in_s, false, true, out);
  }
  if (whole && (!have || out->defects() > 0)) {
    PillowPass all_set;
    const std::vector<uint8_t> all(nh, 1);
    bool ok = attempt(all, true, true, &all_set);
    if (!ok) ok = attempt(all, true, false, &all_set);
    if (ok && (!have || all_set.defects() < out->defects())) {
      *out = std::move(all_set);
      have = true;
    }
  }
  return have;
}

}  // namespace

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
  // Seed hexes join the first pass's forced hexes, or stand alone with seeds_only (pillow_once
  // reads only their hex ids).
  std::vector<ForcedConfiguration> forced;
  if (!params.seeds_only) forced = res.forced;
  std::vector<uint8_t> seeded(complex.hexes.size(), 0);
  for (int32_t h : params.seed_hexes)
    if (h >= 0 && h < static_cast<int32_t>(complex.hexes.size()) && !seeded[h]) {
      seeded[h] = 1;
      forced.push_back({h, -1, ForcedKind::fixed_corner, 0.0});
      ++st.seed_hexes;
    }
  const bool want = params.seeds_only ? !forced.empty()
                                      : params.mode == PillowMode::all ||
                                            (params.mode == PillowMode::automatic && !forced.empty());
  if (!want || complex.hexes.empty()) {
    st.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return res;
  }
  std::vector<int32_t> nb = face_neighbours(complex.hexes);
  std::vector<std::vector<BoundaryCorner>> corners = boundary_corners(surface, complex, nb);
  st.excluded_vertices = count_unserved(corners, std::vector<uint8_t>(complex.hexes.size(), 1));
  // Later passes: a forced hex that had to stay out of S (at a saddle, its quads and those of
  // the other pillowed hexes there have no common inward direction) is pillowed again, locally,
  // with a second copy of the vertex. Each later pass must lower the defects.
  int32_t defects = st.forced;
  int32_t unserved = 0;  // copies without an inward direction, summed over the passes kept
  const int max_passes = std::max(1, params.max_passes);
  for (int pass = 0; pass < max_passes && (pass == 0 || (!forced.empty() && !params.seeds_only));
       ++pass) {
    PillowPass p;
    const bool local = params.mode == PillowMode::automatic || pass > 0;
    if (pass > 0) {  // the complex changed: its faces and boundary corners with it
      nb = face_neighbours(res.complex.hexes);
      corners = boundary_corners(surface, res.complex, nb);
    }
    if (!pillow_once(surface, res.complex, nb, corners, forced, params, local, pass == 0, &p)) {
      if (pass == 0) ctx.warn("pillow: no shrink set gave a ball complex; the mesh is not pillowed");
      break;
    }
    if (pass > 0 && p.defects() + unserved >= defects) break;
    unserved += p.unserved;
    defects = p.forced_after + unserved;
    st.shrink_set += p.set_size;
    st.new_hexes += p.new_hexes;
    st.new_vertices += p.new_vertices;
    st.dropped_hexes += p.dropped;
    st.unserved_vertices = unserved;
    st.forced_after = p.forced_after;
    st.whole_boundary = st.whole_boundary || p.whole;
    st.passes = pass + 1;
    res.complex = std::move(p.complex);
    forced = find_forced_configurations(surface, res.complex, params.forced_sj);
    ctx.report("pillow", (pass + 1.0) / max_passes);
  }
  ctx.report("pillow", 1.0);
  st.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

}  // namespace hexpeel
