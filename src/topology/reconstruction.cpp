// Reconstruction by extrusion and intrusion (paper section 3.3, Kremer et al. 5.3; DESIGN.md
// invariants 2-5).
//
// The complex starts as one hex on the final cube surface and changes by one step per plan
// step, in reverse order. Convex steps extrude: every boundary face on the step's side s gets a
// hex on top, the new top faces take over the quad ids, and each chord quad comes back as a side
// face on the edge it had collapsed into. Patch corners get one copy per fan of patch quads around
// them; a chord that touched itself left a "slit" edge inside the patch that receives two chord
// quads, and the patch is cut open along it. Chord quads' corners come from the records (h, j)
// taken at elimination, never from vertex ids (a merged vertex's representative says nothing about
// its side). Concave steps intrude, the mirror image: the hexes under the side-s faces go.
//
// Assumes a plan with status ok made on `surface` (valid, outward). Guarantees: every hex is a
// positive VTK hex combinatorially (bottom = outward quad), the boundary equals `surface` exactly
// (checked), no vertex is unused; or the status is invalid_intrusion (an intrusion that cannot
// remove exactly |side| hexes cleanly) or internal_error.
#include "hexpeel/reconstruction.h"

#include <algorithm>
#include <chrono>
#include <numeric>
#include <tuple>

namespace hexpeel {
namespace {

using FaceKey = std::array<int32_t, 4>;
FaceKey sorted_key(FaceKey k) {
  std::sort(k.begin(), k.end());
  return k;
}
uint64_t edge_key(int32_t a, int32_t b) {
  if (a > b) std::swap(a, b);
  return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
}

/// The growing complex: hexes and, for every input quad on its boundary, the face's complex
/// vertices in the input quad's corner order.
struct Builder {
  HexComplex k;
  std::vector<Quad> bnd;          ///< per input quad id
  std::vector<uint8_t> on_bnd;    ///< per input quad id

  int32_t new_vertex(int32_t step) {
    k.created_at.push_back(step);
    return k.num_vertices++;
  }
};

Status fail(std::string msg) { return Status::error(StatusCode::internal_error, std::move(msg)); }

/// Invariant 2: the complex's boundary is exactly the quads `ids` with corners `corner_of(q)`
/// (surface vertex ids), through a bijective vertex map.
template <class CornerOf>
Status check_boundary(const Builder& b, const std::vector<int32_t>& ids, int32_t surface_vertices,
                      CornerOf&& corner_of) {
  size_t nb = 0;
  for (uint8_t x : b.on_bnd) nb += x;
  if (nb != ids.size())
    return fail("complex boundary has " + std::to_string(nb) + " faces, surface " +
                std::to_string(ids.size()));
  std::vector<int32_t> phi(b.k.num_vertices, -1), inv(surface_vertices, -1);
  for (int32_t q : ids) {
    if (!b.on_bnd[q]) return fail("quad " + std::to_string(q) + " is not on the complex boundary");
    Quad t = corner_of(q);
    for (int c = 0; c < 4; ++c) {
      int32_t cv = b.bnd[q][c], sv = t[c];
      if (phi[cv] < 0) phi[cv] = sv;
      if (inv[sv] < 0) inv[sv] = cv;
      if (phi[cv] != sv || inv[sv] != cv)
        return fail("vertex map is not a bijection at quad " + std::to_string(q) + " corner " +
                    std::to_string(c));
    }
  }
  std::vector<FaceKey> faces;
  faces.reserve(6 * b.k.hexes.size());
  for (const Hex& h : b.k.hexes)
    for (const auto& lf : kHexFaces) faces.push_back(sorted_key({h[lf[0]], h[lf[1]], h[lf[2]], h[lf[3]]}));
  std::sort(faces.begin(), faces.end());
  std::vector<FaceKey> once;
  for (size_t i = 0; i < faces.size();) {
    size_t j = i;
    while (j < faces.size() && faces[j] == faces[i]) ++j;
    if (j - i > 2) return fail("a face is used by " + std::to_string(j - i) + " hexes");
    if (j - i == 1) once.push_back(faces[i]);
    i = j;
  }
  std::vector<FaceKey> recorded;
  for (int32_t q : ids) recorded.push_back(sorted_key(b.bnd[q]));
  std::sort(recorded.begin(), recorded.end());
  if (recorded != once) return fail("recorded boundary differs from the faces used once");
  return Status::success();
}

Status initial_hex(Builder& b, const EliminationPlan& plan) {
  // Cube vertices: collect, map to complex ids 0..7.
  const auto& fc = plan.final_corners;
  std::vector<int32_t> verts;
  for (const Quad& t : fc) verts.insert(verts.end(), t.begin(), t.end());
  std::sort(verts.begin(), verts.end());
  verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
  if (fc.size() != 6 || verts.size() != 8) return fail("final surface is not a cube");
  auto id = [&](int32_t v) {
    return static_cast<int32_t>(std::lower_bound(verts.begin(), verts.end(), v) - verts.begin());
  };
  std::array<std::vector<int32_t>, 8> nb;
  for (const Quad& t : fc)
    for (int c = 0; c < 4; ++c) {
      int32_t a = id(t[c]), d = id(t[(c + 1) & 3]);
      nb[a].push_back(d);
      nb[d].push_back(a);
    }
  for (auto& n : nb) {
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
    if (n.size() != 3) return fail("final surface vertex without valence 3");
  }
  // The lowest-id surviving quad (a,b,c,d) is the hex's bottom (a,d,c,b) = local face (0,3,2,1).
  const Quad& q0 = fc[0];
  Hex h{};
  int32_t bottom[4] = {id(q0[0]), id(q0[3]), id(q0[2]), id(q0[1])};
  for (int i = 0; i < 4; ++i) {
    h[i] = bottom[i];
    int32_t up = -1;
    for (int32_t x : nb[bottom[i]])
      if (x != bottom[(i + 1) & 3] && x != bottom[(i + 3) & 3]) up = x;
    if (up < 0) return fail("final cube vertex neighbourhood");
    h[i + 4] = up;
  }
  for (int i = 0; i < 8; ++i) b.new_vertex(-1);
  b.k.hexes.push_back(h);
  // Every final quad must be a rotation of an outward face of that hex.
  for (size_t f = 0; f < fc.size(); ++f) {
    Quad t{id(fc[f][0]), id(fc[f][1]), id(fc[f][2]), id(fc[f][3])};
    bool found = false;
    for (const auto& lf : kHexFaces)
      for (int r = 0; r < 4 && !found; ++r)
        found = t[0] == h[lf[r]] && t[1] == h[lf[(r + 1) & 3]] && t[2] == h[lf[(r + 2) & 3]] &&
                t[3] == h[lf[(r + 3) & 3]];
    if (!found) return fail("final quad " + std::to_string(plan.final_quads[f]) + " is not a hex face");
    b.bnd[plan.final_quads[f]] = t;
    b.on_bnd[plan.final_quads[f]] = 1;
  }
  return Status::success();
}

/// The start from a plan's terminal fill (a complex of its stuck final surface), checked against
/// the final quads.
Status terminal_start(Builder& b, const EliminationPlan& plan, int32_t surface_vertices) {
  const TerminalFill& t = plan.terminal;
  if (t.faces.size() != plan.final_quads.size() || plan.final_corners.size() != plan.final_quads.size())
    return fail("terminal fill does not match the final surface");
  for (int32_t v = 0; v < t.num_vertices; ++v) b.new_vertex(-1);
  for (const Hex& h : t.hexes)
    for (int32_t v : h)
      if (v < 0 || v >= t.num_vertices) return fail("terminal fill hex with a bad vertex");
  b.k.hexes = t.hexes;
  for (size_t f = 0; f < t.faces.size(); ++f) {
    const int32_t q = plan.final_quads[f];
    if (q < 0 || q >= static_cast<int32_t>(b.bnd.size())) return fail("terminal fill names a bad quad");
    for (int32_t v : t.faces[f])
      if (v < 0 || v >= t.num_vertices) return fail("terminal fill face with a bad vertex");
    b.bnd[plan.final_quads[f]] = t.faces[f];
    b.on_bnd[plan.final_quads[f]] = 1;
  }
  std::vector<int32_t> final_corner_of(b.bnd.size(), -1);
  for (size_t f = 0; f < plan.final_quads.size(); ++f) final_corner_of[plan.final_quads[f]] = static_cast<int32_t>(f);
  return check_boundary(b, plan.final_quads, surface_vertices,
                        [&](int32_t q) { return plan.final_corners[final_corner_of[q]]; });
}

/// Reverse of one elimination step: extrude the side-s patch.
Status extrude(Builder& b, const PlanStep& st, int32_t step_index, int32_t& slit_count) {
  const auto& region = st.side_quads;  // sorted
  const size_t nr = region.size();
  auto slot_of = [&](int32_t q) -> int32_t {
    auto it = std::lower_bound(region.begin(), region.end(), q);
    return it != region.end() && *it == q ? static_cast<int32_t>(it - region.begin()) : -1;
  };
  for (int32_t q : region)
    if (!b.on_bnd[q]) return fail("side quad " + std::to_string(q) + " is not on the boundary");
  // Edges receiving chord quads: once normally, twice for a slit.
  std::vector<uint64_t> merged;
  for (const ChordQuadRecord& r : st.chord_quads) {
    if (slot_of(r.h) < 0) return fail("side-s neighbour of chord quad " + std::to_string(r.quad) + " is not in the patch");
    merged.push_back(edge_key(b.bnd[r.h][r.j], b.bnd[r.h][(r.j + 1) & 3]));
  }
  std::sort(merged.begin(), merged.end());
  std::vector<uint64_t> slits;
  for (size_t i = 0; i < merged.size();) {
    size_t j = i;
    while (j < merged.size() && merged[j] == merged[i]) ++j;
    if (j - i > 2) return fail("an edge received more than two chord quads");
    if (j - i == 2) slits.push_back(merged[i]);
    i = j;
  }
  slit_count += static_cast<int32_t>(slits.size());
  // Corner slots 4*slot+k; union across interior patch edges that are not slits.
  std::vector<int32_t> par(4 * nr);
  std::iota(par.begin(), par.end(), 0);
  auto find = [&](int32_t x) {
    while (par[x] != x) x = par[x] = par[par[x]];
    return x;
  };
  struct EdgeUse { uint64_t key; int32_t slot; int k; };
  std::vector<EdgeUse> uses;
  uses.reserve(4 * nr);
  for (size_t s = 0; s < nr; ++s)
    for (int k = 0; k < 4; ++k) {
      const Quad& t = b.bnd[region[s]];
      uses.push_back({edge_key(t[k], t[(k + 1) & 3]), static_cast<int32_t>(s), k});
    }
  std::sort(uses.begin(), uses.end(), [](const EdgeUse& x, const EdgeUse& y) {
    return std::tie(x.key, x.slot, x.k) < std::tie(y.key, y.slot, y.k);
  });
  for (size_t i = 0; i < uses.size();) {
    size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key) ++j;
    if (j - i > 2) return fail("patch edge used by more than two patch quads");
    if (j - i == 2 && !std::binary_search(slits.begin(), slits.end(), uses[i].key)) {
      const EdgeUse& u = uses[i];
      const EdgeUse& w = uses[i + 1];
      const Quad& t1 = b.bnd[region[u.slot]];
      const Quad& t2 = b.bnd[region[w.slot]];
      for (int kk : {u.k, (u.k + 1) & 3}) {
        int32_t v = t1[kk];
        int k2 = static_cast<int>(std::find(t2.begin(), t2.end(), v) - t2.begin());
        if (k2 == 4) return fail("patch edge corners do not match");
        int32_t x = find(4 * u.slot + kk), y = find(4 * w.slot + k2);
        if (x != y) par[x] = y;
      }
    }
    i = j;
  }
  std::vector<int32_t> copy(4 * nr, -1), root_copy(4 * nr, -1);
  for (size_t x = 0; x < 4 * nr; ++x) {
    int32_t r = find(static_cast<int32_t>(x));
    if (root_copy[r] < 0) root_copy[r] = b.new_vertex(step_index);
    copy[x] = root_copy[r];
  }
  for (size_t s = 0; s < nr; ++s) {
    const Quad& bot = b.bnd[region[s]];
    b.k.hexes.push_back({bot[0], bot[1], bot[2], bot[3], copy[4 * s], copy[4 * s + 1],
                         copy[4 * s + 2], copy[4 * s + 3]});
  }
  // Chord quads come back on the edges they collapsed into (read h's corners before replacing).
  std::vector<std::pair<int32_t, Quad>> chord_faces;
  for (const ChordQuadRecord& r : st.chord_quads) {
    int32_t hs = slot_of(r.h);
    Quad t{};
    t[r.es] = copy[4 * hs + ((r.j + 1) & 3)];
    t[(r.es + 1) & 3] = copy[4 * hs + r.j];
    t[(r.es + 3) & 3] = b.bnd[r.h][(r.j + 1) & 3];
    t[(r.es + 2) & 3] = b.bnd[r.h][r.j];
    chord_faces.push_back({r.quad, t});
  }
  for (size_t s = 0; s < nr; ++s)
    b.bnd[region[s]] = {copy[4 * s], copy[4 * s + 1], copy[4 * s + 2], copy[4 * s + 3]};
  for (auto& [g, t] : chord_faces) {
    if (b.on_bnd[g]) return fail("chord quad " + std::to_string(g) + " is already on the boundary");
    b.bnd[g] = t;
    b.on_bnd[g] = 1;
  }
  return Status::success();
}

/// Reverse of one concave elimination step (Kremer et al. 5.3): intrude the side-s patch. The
/// hexes under the side-s faces are removed; each side quad takes over the face opposite its
/// old one (in corner order), and each chord quad comes back as the lateral face that hex had on
/// the edge the chord quad collapsed into, now a face of the neighbouring hex. It is the mirror
/// of extrude(). Checked before anything changes: |side| distinct hexes (paper 5.4), each
/// opposite face shared with a hex that stays, each lateral face on a collapsed edge shared with
/// a hex that stays, every other lateral face shared with another intruded hex. Failing any of
/// these is invalid_intrusion and leaves `b` untouched.
Status intrude(Builder& b, const PlanStep& st, int32_t step_index, int32_t& hexes_removed) {
  const auto& region = st.side_quads;  // sorted
  const size_t nr = region.size();
  auto invalid = [&](const std::string& why) {
    return Status::error(StatusCode::invalid_intrusion,
                         "concave step " + std::to_string(step_index) + " (chord " +
                             std::to_string(st.chord) + ", " + std::to_string(nr) +
                             " side quads): " + why);
  };
  auto slot_of = [&](int32_t q) -> int32_t {
    auto it = std::lower_bound(region.begin(), region.end(), q);
    return it != region.end() && *it == q ? static_cast<int32_t>(it - region.begin()) : -1;
  };
  for (int32_t q : region)
    if (!b.on_bnd[q]) return fail("side quad " + std::to_string(q) + " is not on the boundary");
  // Every hex face, sorted by vertex set: face -> hexes.
  struct FaceUse { FaceKey key; int32_t hex; };
  std::vector<FaceUse> faces;
  faces.reserve(6 * b.k.hexes.size());
  for (size_t h = 0; h < b.k.hexes.size(); ++h)
    for (const auto& lf : kHexFaces) {
      const Hex& x = b.k.hexes[h];
      faces.push_back({sorted_key({x[lf[0]], x[lf[1]], x[lf[2]], x[lf[3]]}), static_cast<int32_t>(h)});
    }
  std::sort(faces.begin(), faces.end(), [](const FaceUse& x, const FaceUse& y) {
    return std::tie(x.key, x.hex) < std::tie(y.key, y.hex);
  });
  // The hexes using face `corners` other than `self`: -1 none, -2 more than one.
  auto other_hex = [&](const Quad& corners, int32_t self) {
    FaceKey key = sorted_key(corners);
    auto lo = std::lower_bound(faces.begin(), faces.end(), key,
                               [](const FaceUse& x, const FaceKey& k) { return x.key < k; });
    int32_t other = -1;
    for (auto it = lo; it != faces.end() && it->key == key; ++it)
      if (it->hex != self) other = other < 0 ? it->hex : -2;
    return other;
  };
  std::vector<int32_t> hex_of(nr);
  for (size_t s = 0; s < nr; ++s) {
    const Quad& top = b.bnd[region[s]];
    FaceKey key = sorted_key(top);
    auto lo = std::lower_bound(faces.begin(), faces.end(), key,
                               [](const FaceUse& x, const FaceKey& k) { return x.key < k; });
    if (lo == faces.end() || lo->key != key || (lo + 1 != faces.end() && (lo + 1)->key == key))
      return fail("boundary face of quad " + std::to_string(region[s]) + " is not used by one hex");
    hex_of[s] = lo->hex;
  }
  std::vector<int32_t> intruded = hex_of;
  std::sort(intruded.begin(), intruded.end());
  intruded.erase(std::unique(intruded.begin(), intruded.end()), intruded.end());
  if (intruded.size() != nr)
    return invalid("its faces lie on " + std::to_string(intruded.size()) +
                   " distinct hexes, but an intrusion must remove exactly " + std::to_string(nr) +
                   " (two side faces share a hex, paper 5.4)");
  auto is_intruded = [&](int32_t h) { return h >= 0 && std::binary_search(intruded.begin(), intruded.end(), h); };
  // Records by (h, j): the edges chord quads collapsed into.
  std::vector<std::pair<int32_t, size_t>> rec;  // (4*slot + j, record index)
  for (size_t r = 0; r < st.chord_quads.size(); ++r) {
    const ChordQuadRecord& cr = st.chord_quads[r];
    int32_t hs = slot_of(cr.h);
    if (hs < 0) return fail("side-s neighbour of chord quad " + std::to_string(cr.quad) + " is not in the patch");
    rec.push_back({4 * hs + cr.j, r});
  }
  std::sort(rec.begin(), rec.end());
  // Opposite corners: bottom[4*s+k] lies across the hex edge leaving top corner k.
  std::vector<int32_t> bottom(4 * nr, -1);
  for (size_t s = 0; s < nr; ++s) {
    const Quad& top = b.bnd[region[s]];
    const Hex& x = b.k.hexes[hex_of[s]];
    for (int k = 0; k < 4; ++k) {
      int lk = static_cast<int>(std::find(x.begin(), x.end(), top[k]) - x.begin());
      if (lk == 8) return fail("boundary face corner missing from its hex");
      for (int nbr : kHexCornerFrames[lk])
        if (std::find(top.begin(), top.end(), x[nbr]) == top.end()) bottom[4 * s + k] = x[nbr];
    }
    const int32_t self = hex_of[s];
    const Quad bot{bottom[4 * s], bottom[4 * s + 1], bottom[4 * s + 2], bottom[4 * s + 3]};
    const int32_t under = other_hex(bot, self);
    if (under < 0 || is_intruded(under))
      return invalid("the hex under side quad " + std::to_string(region[s]) +
                     (under == -1 ? " has its opposite face on the boundary"
                                  : " is stacked on another hex of the intrusion"));
    for (int k = 0; k < 4; ++k) {
      const Quad lat{top[k], top[(k + 1) & 3], bottom[4 * s + ((k + 1) & 3)], bottom[4 * s + k]};
      const int32_t nb = other_hex(lat, self);
      const bool collapsed = std::binary_search(
          rec.begin(), rec.end(), std::pair<int32_t, size_t>{4 * static_cast<int32_t>(s) + k, 0},
          [](const auto& x, const auto& y) { return x.first < y.first; });
      if (nb < 0)
        return invalid("the hex under side quad " + std::to_string(region[s]) +
                       " has a side face on the boundary");
      if (collapsed && is_intruded(nb))
        return invalid("a chord quad of side quad " + std::to_string(region[s]) +
                       " would come back between two intruded hexes");
      if (!collapsed && !is_intruded(nb))
        return invalid("the hex under side quad " + std::to_string(region[s]) +
                       " would expose a face that is not a chord quad");
    }
  }
  // Apply: chord quads first (they read the old top corners), then the side quads, then the hexes.
  std::vector<std::pair<int32_t, Quad>> chord_faces;
  for (const ChordQuadRecord& r : st.chord_quads) {
    const int32_t hs = slot_of(r.h);
    Quad t{};
    t[r.es] = bottom[4 * hs + ((r.j + 1) & 3)];
    t[(r.es + 1) & 3] = bottom[4 * hs + r.j];
    t[(r.es + 3) & 3] = b.bnd[r.h][(r.j + 1) & 3];
    t[(r.es + 2) & 3] = b.bnd[r.h][r.j];
    if (b.on_bnd[r.quad]) return fail("chord quad " + std::to_string(r.quad) + " is already on the boundary");
    chord_faces.push_back({r.quad, t});
  }
  for (size_t s = 0; s < nr; ++s)
    b.bnd[region[s]] = {bottom[4 * s], bottom[4 * s + 1], bottom[4 * s + 2], bottom[4 * s + 3]};
  for (auto& [g, t] : chord_faces) {
    b.bnd[g] = t;
    b.on_bnd[g] = 1;
  }
  std::vector<Hex> kept;
  kept.reserve(b.k.hexes.size() - nr);
  for (size_t h = 0; h < b.k.hexes.size(); ++h)
    if (!is_intruded(static_cast<int32_t>(h))) kept.push_back(b.k.hexes[h]);
  b.k.hexes = std::move(kept);
  hexes_removed += static_cast<int32_t>(nr);
  return Status::success();
}

/// Removes vertices no hex uses (left by intrusions) and renumbers the rest in order.
int32_t remove_unused_vertices(Builder& b) {
  std::vector<int32_t> to_new(b.k.num_vertices, -1);
  for (const Hex& h : b.k.hexes)
    for (int32_t v : h) to_new[v] = 0;
  int32_t next = 0;
  for (int32_t v = 0; v < b.k.num_vertices; ++v)
    if (to_new[v] == 0) {
      b.k.created_at[next] = b.k.created_at[v];
      to_new[v] = next++;
    }
  const int32_t removed = b.k.num_vertices - next;
  if (removed == 0) return 0;
  b.k.created_at.resize(next);
  b.k.num_vertices = next;
  for (Hex& h : b.k.hexes)
    for (int32_t& v : h) v = to_new[v];
  for (size_t q = 0; q < b.bnd.size(); ++q)
    if (b.on_bnd[q])
      for (int32_t& v : b.bnd[q]) v = to_new[v];
  return removed;
}

}  // namespace

ReconstructionResult run_reconstruction(const QuadSurface& surface, const EliminationPlan& plan,
                                        const ReconstructionParams& params, const Context& ctx,
                                        EliminationState* replay) {
  const auto t0 = std::chrono::steady_clock::now();
  ReconstructionResult res;
  if (!plan.status.ok()) {
    res.status = fail("reconstruction needs a complete plan");
    return res;
  }
  Builder b;
  b.bnd.assign(surface.num_quads(), Quad{-1, -1, -1, -1});
  b.on_bnd.assign(surface.num_quads(), 0);
  res.status = plan.terminal.empty() ? initial_hex(b, plan)
                                      : terminal_start(b, plan, surface.num_points());
  const bool verify = params.verify_each_step && replay != nullptr &&
                      replay->steps_applied() == static_cast<int32_t>(plan.steps.size());
  std::vector<int32_t> ids;
  auto verify_now = [&]() {
    replay->current_surface(&ids);
    res.status = check_boundary(b, ids, surface.num_points(), [&](int32_t q) { return replay->corners(q); });
    ++res.stats.steps_verified;
  };
  // With a replay, every step undoes it (intrusions are always checked against it).
  const bool replay_ok = replay != nullptr &&
                         replay->steps_applied() == static_cast<int32_t>(plan.steps.size());
  if (res.status.ok() && verify) verify_now();
  const int32_t n = static_cast<int32_t>(plan.steps.size());
  for (int32_t i = n - 1; i >= 0 && res.status.ok(); --i) {
    const PlanStep& st = plan.steps[i];
    bool extruded = !st.concave;
    if (st.concave) {
      // Intrude; an intrusion that passes its local checks but leaves a boundary other than the
      // intermediate surface (checked whenever `replay` is given) is invalid too.
      Builder before = b;
      int32_t removed = 0;
      res.status = intrude(b, st, i, removed);
      if (res.status.ok() && replay_ok) {
        replay->undo();
        verify_now();
        if (!res.status.ok()) {
          res.status = Status::error(StatusCode::invalid_intrusion,
                                     "concave step " + std::to_string(i) + " (chord " +
                                         std::to_string(st.chord) +
                                         "): the boundary after intrusion is not the surface "
                                         "before the step: " + res.status.message);
          b = std::move(before);
        }
      }
      if (res.status.ok()) {
        ++res.stats.intrusions;
        res.stats.hexes_intruded += removed;
      } else if (res.status.code == StatusCode::invalid_intrusion) {
        res.stats.invalid_intrusion_steps.push_back(i);
        if (!params.fallback_to_extrusion) break;
        ctx.warn(res.status.message + "; extruded instead");
        extruded = true;
      } else {
        res.status.message = "reconstruction of step " + std::to_string(i) + ": " + res.status.message;
        break;
      }
    }
    if (extruded) {
      res.status = extrude(b, st, i, res.stats.slit_edges);
      if (!res.status.ok()) {
        res.status.message = "reconstruction of step " + std::to_string(i) + ": " + res.status.message;
        break;
      }
      if (replay_ok) {
        if (replay->steps_applied() == i + 1) replay->undo();
        if (verify || st.concave) {
          verify_now();
          if (!res.status.ok())
            res.status.message = "after reconstructing step " + std::to_string(i) + ": " + res.status.message;
        }
      }
    }
    ctx.report("reconstruction", static_cast<double>(n - i) / std::max(1, n));
  }
  if (res.status.ok() && res.stats.intrusions > 0) res.stats.vertices_removed = remove_unused_vertices(b);
  if (res.status.ok()) {
    // Invariant 5: the final boundary is the input surface, by quad id and corner order.
    ids.resize(surface.num_quads());
    std::iota(ids.begin(), ids.end(), 0);
    res.status = check_boundary(b, ids, surface.num_points(), [&](int32_t q) { return surface.quads[q]; });
  }
  if (res.status.ok()) {
    b.k.input_vertex.assign(b.k.num_vertices, -1);
    for (int32_t q = 0; q < surface.num_quads(); ++q)
      for (int c = 0; c < 4; ++c) b.k.input_vertex[b.bnd[q][c]] = surface.quads[q][c];
    res.complex = std::move(b.k);
  }
  res.stats.hexes = static_cast<int32_t>(res.complex.hexes.size());
  res.stats.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

}  // namespace hexpeel
