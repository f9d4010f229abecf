// Reconstruction by extrusion (paper section 3.3; DESIGN.md invariants 2, 3, 5).
//
// The complex starts as one hex on the final cube surface and grows by one extrusion per plan
// step, in reverse order: every boundary face on the step's side s gets a hex on top, the new top
// faces take over the quad ids, and each chord quad comes back as a side face on the edge it had
// collapsed into. Patch corners get one copy per fan of patch quads around them; a chord that
// touched itself left a "slit" edge inside the patch that receives two chord quads, and the patch
// is cut open along it. Chord quads' corners come from the records (h, j) taken at elimination,
// never from vertex ids (a merged vertex's representative says nothing about its side).
//
// Assumes a plan with status ok made on `surface` (valid, outward). Guarantees: every hex is a
// positive VTK hex combinatorially (bottom = outward quad), the boundary equals `surface` exactly
// (checked), or the status is internal_error.
#include "hexpeel/reconstruction.h"

#include <algorithm>
#include <chrono>
#include <numeric>

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
  res.status = initial_hex(b, plan);
  const bool verify = params.verify_each_step && replay != nullptr &&
                      replay->steps_applied() == static_cast<int32_t>(plan.steps.size());
  std::vector<int32_t> ids;
  auto verify_now = [&]() {
    replay->current_surface(&ids);
    res.status = check_boundary(b, ids, surface.num_points(), [&](int32_t q) { return replay->corners(q); });
    ++res.stats.steps_verified;
  };
  if (res.status.ok() && verify) verify_now();
  const int32_t n = static_cast<int32_t>(plan.steps.size());
  for (int32_t i = n - 1; i >= 0 && res.status.ok(); --i) {
    const PlanStep& st = plan.steps[i];
    if (st.concave) {
      res.status = Status::error(StatusCode::internal_error,
                                 "concave steps (intrusion) are not implemented yet");
      break;
    }
    res.status = extrude(b, st, i, res.stats.slit_edges);
    if (!res.status.ok()) {
      res.status.message = "reconstruction of step " + std::to_string(i) + ": " + res.status.message;
      break;
    }
    if (verify) {
      replay->undo();
      verify_now();
      if (!res.status.ok())
        res.status.message = "after reconstructing step " + std::to_string(i) + ": " + res.status.message;
    }
    ctx.report("reconstruction", static_cast<double>(n - i) / std::max(1, n));
  }
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
