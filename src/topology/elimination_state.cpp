// EliminationState: the intermediate surface of dual cycle elimination, undoable.
//
// Implements paper section 3.1 (collapsing a chord on the primal mesh) and the feasibility test
// of 3.2 by the local check of DESIGN.md "Terms": the collapse is simulated on the quads around
// the strip only, and the result must keep 4 distinct corners per quad, valence >= 3, two quads
// per edge, no two quads sharing two vertices unless they share the edge between them, a single
// fan of quads around every merged vertex and the Euler characteristic.
//
// Assumes a valid input surface (closed, manifold, genus 0). Guarantees: quads keep their input
// ids and corner order (invariant 1); apply() followed by undo() restores every array exactly.
#include "hexpeel/elimination_state.h"

#include <algorithm>
#include <numeric>
#include <utility>

namespace hexpeel {

std::string_view to_string(Infeasible why) {
  switch (why) {
    case Infeasible::none: return "feasible";
    case Infeasible::self_intersecting: return "self-intersecting";
    case Infeasible::no_connected_side: return "no edge-connected side";
    case Infeasible::degenerate_face: return "a quad would degenerate";
    case Infeasible::nonmanifold_edge: return "an edge would not have two quads";
    case Infeasible::low_valence: return "a vertex would have valence < 3";
    case Infeasible::face_pair: return "two quads would share two vertices without an edge";
    case Infeasible::pinched_vertex: return "a vertex would be pinched";
    case Infeasible::euler: return "the Euler characteristic would change";
    case Infeasible::too_few_chords: return "only the cube's chords are left";
  }
  return "?";
}

namespace {
/// Advances an epoch counter for a stamp array, clearing the array when the counter wraps.
int32_t next_epoch(int32_t& epoch, std::vector<int32_t>& stamps) {
  if (++epoch == 0) {
    std::fill(stamps.begin(), stamps.end(), 0);
    epoch = 1;
  }
  return epoch;
}
inline int32_t he_of(int32_t q, int k) { return 4 * q + (k & 3); }
inline uint64_t edge_key(int32_t a, int32_t b) {
  if (a > b) std::swap(a, b);
  return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
}
}  // namespace

EliminationState::EliminationState(const QuadSurface& surface, const ChordSet& chords,
                                   const EdgeGeometry& edges)
    : surface_(&surface), chords_(&chords) {
  const int32_t nq = surface.num_quads();
  const int32_t nv = surface.num_points();
  quad_alive_.assign(nq, 1);
  alive_quads_ = nq;
  chord_len_.resize(chords.chords.size());
  for (size_t c = 0; c < chords.chords.size(); ++c)
    chord_len_[c] = static_cast<int32_t>(chords.chords[c].steps.size());
  alive_chords_ = static_cast<int32_t>(chords.chords.size());
  opp_ = build_adjacency(surface).opposite;
  weight_.resize(4 * static_cast<size_t>(nq));
  for (size_t he = 0; he < weight_.size(); ++he) {
    EdgeKind k = he < edges.kind.size() ? edges.kind[he] : EdgeKind::flat;
    weight_[he].sharp = k != EdgeKind::flat;
    weight_[he].convex = k == EdgeKind::convex;
    weight_[he].concave = k == EdgeKind::concave;
    weight_[he].bend = he < edges.bend_deg.size() ? edges.bend_deg[he] : 0.0;
  }
  uf_parent_.resize(nv);
  std::iota(uf_parent_.begin(), uf_parent_.end(), 0);
  uf_rank_.assign(nv, 0);
  stamp_.assign(nq, 0);
  cmark_.assign(nq, 0);
  local_parent_.assign(nv, -1);
  vstamp_.assign(nv, 0);
  rstamp_.assign(nv, 0);
  qstamp_.assign(nq, 0);
  chord_hits_.assign(chords.chords.size(), 0);
  chord_version_.assign(chords.chords.size(), 1);
  weights_version_.assign(chords.chords.size(), 0);
  weights_cache_.resize(chords.chords.size());
}

int32_t EliminationState::find(int32_t v) const {
  while (uf_parent_[v] != v) v = uf_parent_[v];
  return v;
}

void EliminationState::chord_steps(int32_t c, std::vector<ChordStep>& out) const {
  out.clear();
  for (const ChordStep& s : chords_->chords[c].steps)
    if (quad_alive_[s.quad]) out.push_back(s);
}

Quad EliminationState::corners(int32_t q) const {
  const Quad& f = surface_->quads[q];
  return {find(f[0]), find(f[1]), find(f[2]), find(f[3])};
}

ChordWeights EliminationState::weights(int32_t c) const {
  // cached until a quad of c changes (alive flag or edge weights: touch_quad)
  if (weights_version_[c] == chord_version_[c]) return weights_cache_[c];
  ChordWeights& w = weights_cache_[c];
  w = ChordWeights{};
  weights_version_[c] = chord_version_[c];
  for (const ChordStep& s : chords_->chords[c].steps) {
    if (!quad_alive_[s.quad]) continue;
    ++w.length;
    const EdgeWeight& l = weight_[he_of(s.quad, s.edge + 3)];
    const EdgeWeight& r = weight_[he_of(s.quad, s.edge + 1)];
    w.sharp[0] += l.sharp, w.sharp[1] += r.sharp;
    w.convex[0] += l.convex, w.convex[1] += r.convex;
    w.concave[0] += l.concave, w.concave[1] += r.concave;
    w.crossing_sharp += weight_[he_of(s.quad, s.edge)].sharp;
  }
  if (w.length > 0)
    for (int s = 0; s < 2; ++s) {
      w.sharp[s] /= w.length;
      w.convex[s] /= w.length;
      w.concave[s] /= w.length;
    }
  return w;
}

void EliminationState::mark_chord_quads(const std::vector<ChordStep>& steps) const {
  if (++cepoch_ == 0) {  // wrapped: clear
    std::fill(cmark_.begin(), cmark_.end(), 0);
    cepoch_ = 1;
  }
  for (const ChordStep& s : steps) cmark_[s.quad] = cepoch_;
}

void EliminationState::side_region(int32_t c, int side, std::vector<int32_t>& out) const {
  chord_steps(c, scratch_steps_);
  mark_chord_quads(scratch_steps_);
  out.clear();
  if (++epoch_ == 0) {
    std::fill(stamp_.begin(), stamp_.end(), 0);
    epoch_ = 1;
  }
  for (const ChordStep& s : scratch_steps_) {
    int32_t h = opp_[he_of(s.quad, s.edge + (side == 0 ? 3 : 1))] >> 2;
    if (is_marked(h) || stamp_[h] == epoch_) continue;
    stamp_[h] = epoch_;
    out.push_back(h);
    // depth-first flood from this seed; `out` doubles as the stack's storage
    for (size_t top = out.size() - 1; top < out.size(); ++top) {
      int32_t g = out[top];
      for (int k = 0; k < 4; ++k) {
        int32_t n = opp_[he_of(g, k)] >> 2;
        if (is_marked(n) || stamp_[n] == epoch_) continue;
        stamp_[n] = epoch_;
        out.push_back(n);
      }
    }
  }
  std::sort(out.begin(), out.end());
}

int32_t EliminationState::side_size(int32_t c, int side) const {
  if (!sizes_valid_) compute_side_sizes();
  return side_sizes_[c][side];
}

void EliminationState::compute_side_sizes() const {
  // Spanning tree of the dual graph (alive quads, breadth first), subtree sizes; the quads on a
  // side of chord c are then the net subtree flux through c's parallel edges on that side:
  // tree edges entering the side add their child's subtree, edges leaving it subtract the
  // chord quad's subtree; a non-positive total means the root is on that side (add all quads).
  const int32_t nq = surface_->num_quads();
  tree_parent_.assign(nq, -1);
  tree_size_.assign(nq, 0);
  std::vector<int32_t> order;
  order.reserve(alive_quads_);
  int32_t root = -1;
  for (int32_t q = 0; q < nq && root < 0; ++q)
    if (quad_alive_[q]) root = q;
  const int32_t ep = next_epoch(epoch_, stamp_);
  if (root >= 0) {
    order.push_back(root);
    stamp_[root] = ep;
  }
  for (size_t i = 0; i < order.size(); ++i)
    for (int k = 0; k < 4; ++k) {
      int32_t n = opp_[he_of(order[i], k)] >> 2;
      if (stamp_[n] == ep) continue;
      stamp_[n] = ep;
      tree_parent_[n] = order[i];
      order.push_back(n);
    }
  for (size_t i = order.size(); i-- > 0;) {
    tree_size_[order[i]] += 1;
    if (tree_parent_[order[i]] >= 0) tree_size_[tree_parent_[order[i]]] += tree_size_[order[i]];
  }
  const int32_t n_alive = static_cast<int32_t>(order.size());
  side_sizes_.assign(chords_->chords.size(), {0, 0});
  for (size_t c = 0; c < chords_->chords.size(); ++c) {
    if (chord_len_[c] == 0 || chords_->chords[c].self_intersecting) continue;
    auto in_chord = [&](int32_t q) {
      return chords_->chord_of[2 * q] == static_cast<int32_t>(c) ||
             chords_->chord_of[2 * q + 1] == static_cast<int32_t>(c);
    };
    for (int side = 0; side < 2; ++side) {
      int64_t flux = 0;
      bool any = false;
      for (const ChordStep& st : chords_->chords[c].steps) {
        if (!quad_alive_[st.quad]) continue;
        int32_t h = opp_[he_of(st.quad, st.edge + (side == 0 ? 3 : 1))] >> 2;
        if (in_chord(h)) continue;
        any = true;
        if (tree_parent_[h] == st.quad) flux += tree_size_[h];
        else if (tree_parent_[st.quad] == h) flux -= tree_size_[st.quad];
      }
      side_sizes_[c][side] = any ? static_cast<int32_t>(flux > 0 ? flux : flux + n_alive) : 0;
    }
  }
  sizes_valid_ = true;
}

bool EliminationState::side_usable(const std::vector<ChordStep>& steps, int side) const {
  // Chord quads must be marked by the caller. A side is usable when it has quads, none of its
  // chord quads' side-s neighbours is itself a chord quad (reconstruction needs a patch quad
  // there), and its quads are edge-connected.
  std::vector<int32_t> seeds;
  seeds.reserve(steps.size());
  for (const ChordStep& s : steps) {
    int32_t h = opp_[he_of(s.quad, s.edge + (side == 0 ? 3 : 1))] >> 2;
    if (is_marked(h)) return false;
    seeds.push_back(h);
  }
  if (seeds.empty()) return false;
  // Fast path: if the side's boundary curve visits distinct vertices it is a simple closed curve
  // on a sphere, which bounds a disk: the side is connected.
  std::vector<int32_t> curve;
  curve.reserve(steps.size());
  for (const ChordStep& s : steps)
    curve.push_back(find(surface_->quads[s.quad][(s.edge + (side == 0 ? 0 : 1)) & 3]));
  std::sort(curve.begin(), curve.end());
  if (std::adjacent_find(curve.begin(), curve.end()) == curve.end()) return true;
  // Exact: flood from the first seed and check every seed is reached.
  if (++epoch_ == 0) {
    std::fill(stamp_.begin(), stamp_.end(), 0);
    epoch_ = 1;
  }
  std::vector<int32_t> stack{seeds[0]};
  stamp_[seeds[0]] = epoch_;
  while (!stack.empty()) {
    int32_t g = stack.back();
    stack.pop_back();
    for (int k = 0; k < 4; ++k) {
      int32_t n = opp_[he_of(g, k)] >> 2;
      if (is_marked(n) || stamp_[n] == epoch_) continue;
      stamp_[n] = epoch_;
      stack.push_back(n);
    }
  }
  for (int32_t h : seeds)
    if (stamp_[h] != epoch_) return false;
  return true;
}

Infeasible EliminationState::collapse_test(const std::vector<ChordStep>& steps) const {
  // Chord quads are marked by the caller. Trial merges live in local_parent_ (reset at the end).
  auto& touched = cs_.touched;
  touched.clear();
  auto lfind = [&](int32_t v) {
    int32_t r = find(v);
    while (local_parent_[r] >= 0) r = local_parent_[r];
    return r;
  };
  for (const ChordStep& s : steps) {
    const Quad& f = surface_->quads[s.quad];
    int32_t a = lfind(f[s.edge & 3]), b = lfind(f[(s.edge + 1) & 3]);
    if (a == b) continue;
    if (a < b) std::swap(a, b);
    local_parent_[a] = b;
    touched.push_back(a);
  }
  auto reset = [&] {
    for (int32_t v : touched) local_parent_[v] = -1;
  };

  // VC: current vertices of the chord quads (one (quad, corner) kept per vertex); rotate around
  // each to find the quads touching them. Stamps replace sorting for the deduplication.
  const int32_t vep = next_epoch(vepoch_, vstamp_);
  auto& vc = cs_.vc;
  auto& vc_corner = cs_.vc_corner;
  vc.clear();
  vc_corner.clear();
  for (const ChordStep& s : steps)
    for (int k = 0; k < 4; ++k) {
      int32_t v = find(surface_->quads[s.quad][k]);
      if (vstamp_[v] == vep) continue;
      vstamp_[v] = vep;
      vc.push_back(v);
      vc_corner.push_back({s.quad, k});
    }
  auto in_vc = [&](int32_t v) { return vstamp_[v] == vep; };
  auto rotate = [&](int32_t q, int k, auto&& visit) {
    // visits every (quad, corner) around the vertex at corner k of q
    int32_t q0 = q;
    int k0 = k;
    int guard = 0;
    do {
      visit(q, k);
      int32_t he = opp_[he_of(q, k + 3)];
      q = he >> 2;
      k = he & 3;
      HEXPEEL_ASSERT(++guard < 1 << 24);
    } while (q != q0 || k != k0);
  };
  const int32_t qep = next_epoch(qepoch_, qstamp_);
  auto& faces_a = cs_.faces_a;            // non-chord quads touching VC
  auto& vc_faces_all = cs_.vc_faces_all;  // chord + non-chord quads touching VC (Euler count)
  faces_a.clear();
  vc_faces_all.clear();
  for (auto& qc : vc_corner)
    rotate(qc.first, qc.second, [&](int32_t q, int) {
      if (qstamp_[q] == qep) return;
      qstamp_[q] = qep;
      vc_faces_all.push_back(q);
      if (!is_marked(q)) faces_a.push_back(q);
    });

  // New corners of the touching quads.
  auto& newf = cs_.newf;
  newf.resize(faces_a.size());
  for (size_t i = 0; i < faces_a.size(); ++i) {
    const Quad& f = surface_->quads[faces_a[i]];
    for (int k = 0; k < 4; ++k) newf[i][k] = lfind(f[k]);
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        if (newf[i][a] == newf[i][b]) return reset(), Infeasible::degenerate_face;
  }
  // R: merged vertices (images of VC).
  auto& rset = cs_.rset;
  rset.clear();
  for (int32_t v : vc) rset.push_back(lfind(v));
  const int32_t rep = next_epoch(repoch_, rstamp_);
  for (int32_t v : rset) rstamp_[v] = rep;
  auto in_r = [&](int32_t v) { return rstamp_[v] == rep; };

  // Edges touching R: (key, face index) pairs; every key must appear exactly twice.
  auto& ekeys = cs_.ekeys;
  auto& nbr = cs_.nbr;  // (r, neighbour)
  ekeys.clear();
  nbr.clear();
  for (size_t i = 0; i < newf.size(); ++i)
    for (int k = 0; k < 4; ++k) {
      int32_t a = newf[i][k], b = newf[i][(k + 1) & 3];
      bool ra = in_r(a), rb = in_r(b);
      if (ra || rb) ekeys.push_back({edge_key(a, b), static_cast<int32_t>(i)});
      if (ra) nbr.push_back({a, b});
      if (rb) nbr.push_back({b, a});
    }
  std::sort(ekeys.begin(), ekeys.end());
  for (size_t i = 0; i < ekeys.size();) {
    size_t j = i;
    while (j < ekeys.size() && ekeys[j].first == ekeys[i].first) ++j;
    if (j - i != 2) return reset(), Infeasible::nonmanifold_edge;
    i = j;
  }
  std::sort(nbr.begin(), nbr.end());
  nbr.erase(std::unique(nbr.begin(), nbr.end()), nbr.end());
  auto& rlive = cs_.rlive;
  rlive.clear();
  for (size_t i = 0; i < nbr.size();) {
    size_t j = i;
    while (j < nbr.size() && nbr[j].first == nbr[i].first) ++j;
    if (j - i < 3) return reset(), Infeasible::low_valence;
    rlive.push_back(nbr[i].first);
    i = j;
  }
  // Unmerged neighbours of merged vertices may lose an edge (two of their edges merge).
  auto& x_corner = cs_.x_corner;
  x_corner.clear();
  for (size_t i = 0; i < newf.size(); ++i)
    for (int k = 0; k < 4; ++k)
      if (!in_r(newf[i][k]) && (in_r(newf[i][(k + 1) & 3]) || in_r(newf[i][(k + 3) & 3])))
        x_corner.push_back({faces_a[i], k});
  {
    auto& tmp = cs_.xs;
    tmp.clear();
    for (auto& qc : x_corner) tmp.push_back({find(surface_->quads[qc.first][qc.second]), qc});
    std::sort(tmp.begin(), tmp.end());
    tmp.erase(std::unique(tmp.begin(), tmp.end(),
                          [](auto& x, auto& y) { return x.first == y.first; }),
              tmp.end());
    auto& around = cs_.around;
    for (auto& t : tmp) {
      around.clear();
      rotate(t.second.first, t.second.second, [&](int32_t q, int k) {
        const Quad& f = surface_->quads[q];
        around.push_back(lfind(f[(k + 1) & 3]));
        around.push_back(lfind(f[(k + 3) & 3]));
      });
      std::sort(around.begin(), around.end());
      if (std::unique(around.begin(), around.end()) - around.begin() < 3)
        return reset(), Infeasible::low_valence;
    }
  }
  // Quads around each merged vertex: pairs sharing >= 2 vertices must share exactly an edge;
  // and the quads must form one fan (connected through edges at that vertex).
  auto& at = cs_.at;
  auto& links = cs_.links;
  // (merged vertex, face index) pairs, grouped by vertex
  auto& faces_at = cs_.faces_at;
  faces_at.clear();
  for (size_t i = 0; i < newf.size(); ++i)
    for (int k = 0; k < 4; ++k)
      if (in_r(newf[i][k])) faces_at.push_back({newf[i][k], static_cast<int32_t>(i)});
  std::sort(faces_at.begin(), faces_at.end());
  size_t fa = 0;
  for (int32_t r : rlive) {
    at.clear();
    while (fa < faces_at.size() && faces_at[fa].first < r) ++fa;
    for (; fa < faces_at.size() && faces_at[fa].first == r; ++fa) at.push_back(faces_at[fa].second);
    for (size_t a = 0; a < at.size(); ++a)
      for (size_t b = a + 1; b < at.size(); ++b) {
        const Quad& ta = newf[at[a]];
        const Quad& tb = newf[at[b]];
        int shared = 0;
        int pa[4], pb[4];
        for (int x = 0; x < 4; ++x)
          for (int y = 0; y < 4; ++y)
            if (ta[x] == tb[y]) pa[shared] = x, pb[shared] = y, ++shared;
        if (shared >= 3) return reset(), Infeasible::face_pair;
        if (shared == 2) {
          int da = (pa[0] - pa[1] + 4) & 3, db = (pb[0] - pb[1] + 4) & 3;
          if (da == 2 || db == 2) return reset(), Infeasible::face_pair;
        }
      }
    // fan connectivity: link quads that share an edge (r, x)
    links.clear();
    for (int32_t i : at) {
      const Quad& t = newf[i];
      int k = static_cast<int>(std::find(t.begin(), t.end(), r) - t.begin());
      links.push_back({t[(k + 1) & 3], i});
      links.push_back({t[(k + 3) & 3], i});
    }
    std::sort(links.begin(), links.end());
    // union-find over `at` positions
    auto& par = cs_.par;
    par.resize(at.size());
    std::iota(par.begin(), par.end(), 0);
    auto pos = [&](int32_t face) {
      return static_cast<int32_t>(std::lower_bound(at.begin(), at.end(), face) - at.begin());
    };
    auto pf = [&](int32_t x) {
      while (par[x] != x) x = par[x] = par[par[x]];
      return x;
    };
    int comps = static_cast<int>(at.size());
    for (size_t i = 0; i + 1 < links.size(); ++i)
      if (links[i].first == links[i + 1].first) {
        int32_t a = pf(pos(links[i].second)), b = pf(pos(links[i + 1].second));
        if (a != b) par[a] = b, --comps;
      }
    if (comps != 1) return reset(), Infeasible::pinched_vertex;
  }
  // Euler characteristic: removed vertices - removed edges + removed faces must balance.
  auto& old_edges = cs_.old_edges;
  old_edges.clear();
  for (int32_t q : vc_faces_all) {
    const Quad& f = surface_->quads[q];
    for (int k = 0; k < 4; ++k) {
      int32_t a = find(f[k]), b = find(f[(k + 1) & 3]);
      if (in_vc(a) || in_vc(b)) old_edges.push_back(edge_key(a, b));
    }
  }
  std::sort(old_edges.begin(), old_edges.end());
  int64_t n_old_edges = std::unique(old_edges.begin(), old_edges.end()) - old_edges.begin();
  int64_t n_new_edges = static_cast<int64_t>(ekeys.size() / 2);
  int64_t dv = static_cast<int64_t>(vc.size()) - static_cast<int64_t>(rlive.size());
  int64_t de = n_old_edges - n_new_edges;
  int64_t df = static_cast<int64_t>(steps.size());
  reset();
  if (de - dv - df != 0) return Infeasible::euler;
  return Infeasible::none;
}

int32_t EliminationState::valence(int32_t q, int k) const {
  // quads around the vertex at corner k of q (= its edges: the surface is a closed manifold)
  int32_t n = 0, g = q;
  int kk = k & 3;
  do {
    ++n;
    const int32_t he = opp_[he_of(g, kk + 3)];
    g = he >> 2;
    kk = he & 3;
  } while (g != q || kk != (k & 3));
  return n;
}

EliminationState::Feasibility EliminationState::feasibility(int32_t c) const {
  Feasibility f;
  if (chords_->chords[c].self_intersecting) {
    f.why = Infeasible::self_intersecting;
    return f;
  }
  if (alive_chords_ <= 3 || chord_len_[c] == 0) {
    f.why = Infeasible::too_few_chords;
    return f;
  }
  std::vector<ChordStep> steps;
  chord_steps(c, steps);
  mark_chord_quads(steps);
  // A chord crossing c only inside c's quads would vanish: never feasible.
  for (const ChordStep& s : steps) ++chord_hits_[chords_->chord_of[2 * s.quad + ((s.edge + 1) & 1)]];
  bool vanishes = false;
  for (const ChordStep& s : steps) {
    int32_t d = chords_->chord_of[2 * s.quad + ((s.edge + 1) & 1)];
    if (chord_hits_[d] >= chord_len_[d]) vanishes = true;
  }
  for (const ChordStep& s : steps) chord_hits_[chords_->chord_of[2 * s.quad + ((s.edge + 1) & 1)]] = 0;
  if (vanishes) {
    f.why = Infeasible::degenerate_face;
    return f;
  }
  f.sides = {side_usable(steps, 0), side_usable(steps, 1)};
  if (!f.sides[0] && !f.sides[1]) {
    f.why = Infeasible::no_connected_side;
    return f;
  }
  // Cheap exact shortcut for the commonest failure: a crossed edge whose two ends both have
  // valence 3 lies between the two chord quads and one more quad at each end, so its merged
  // vertex would keep at most two edges.
  for (const ChordStep& s : steps)
    if (valence(s.quad, s.edge) == 3 && valence(s.quad, s.edge + 1) == 3) {
      f.why = Infeasible::low_valence;
      return f;
    }
  f.why = collapse_test(steps);
  return f;
}

Infeasible EliminationState::collapse_check(int32_t c) const {
  std::vector<ChordStep> steps;
  chord_steps(c, steps);
  mark_chord_quads(steps);
  return collapse_test(steps);
}

void EliminationState::set_opp(int32_t he, int32_t value) {
  log_.push_back({LogEntry::opp, he, opp_[he], {}});
  opp_[he] = value;
}

void EliminationState::set_weight(int32_t he, const EdgeWeight& w) {
  log_.push_back({LogEntry::weight, he, 0, weight_[he]});
  weight_[he] = w;
  touch_quad(he >> 2);
}

void EliminationState::touch_quad(int32_t q) {
  // both chords through q read q's alive flag and edge weights
  const uint64_t v = ++version_counter_;
  chord_version_[chords_->chord_of[2 * q]] = v;
  chord_version_[chords_->chord_of[2 * q + 1]] = v;
}

PlanStep EliminationState::apply(int32_t c, int side) {
  PlanStep step;
  step.chord = c;
  step.side = static_cast<int8_t>(side);
  side_region(c, side, step.side_quads);
  chord_steps(c, scratch_steps_);
  mark_chord_quads(scratch_steps_);
  for (const ChordStep& s : scratch_steps_) {
    int8_t es = static_cast<int8_t>((s.edge + (side == 0 ? 3 : 1)) & 3);
    int32_t he = opp_[he_of(s.quad, es)];
    HEXPEEL_ASSERT_MSG(!is_marked(he >> 2), "side-s neighbour of a chord quad is a chord quad");
    step.chord_quads.push_back({s.quad, es, he >> 2, static_cast<int8_t>(he & 3)});
  }
  collapse(c);
  return step;
}

void EliminationState::chord_sides(int32_t c, std::vector<int8_t>& out) const {
  out.assign(chords_->chords.size(), -1);
  const std::array<int32_t, 2> size{side_size(c, 0), side_size(c, 1)};
  const int small = size[1] < size[0] ? 1 : 0;
  // The sides partition the rest of the surface unless the chord touches itself so that a region
  // borders both sides; then both are flooded.
  const bool partition = size[0] + size[1] + chord_len_[c] == alive_quads_;
  std::vector<int32_t> region, other;
  if (!partition) side_region(c, 1 - small, other);  // sorted
  side_region(c, small, region);  // stamps the region with epoch_, marks c's quads
  std::vector<uint8_t> crossing(chords_->chords.size(), 0);
  for (const ChordStep& s : chords_->chords[c].steps)
    if (quad_alive_[s.quad]) crossing[chords_->chord_of[2 * s.quad + ((s.edge + 1) & 1)]] = 1;
  for (size_t d = 0; d < chords_->chords.size(); ++d) {
    if (static_cast<int32_t>(d) == c || chord_len_[d] == 0 || crossing[d]) continue;
    int32_t q = -1;
    for (const ChordStep& s : chords_->chords[d].steps)
      if (quad_alive_[s.quad]) {
        q = s.quad;
        break;
      }
    if (stamp_[q] == epoch_) out[d] = static_cast<int8_t>(small);
    else if (partition || std::binary_search(other.begin(), other.end(), q))
      out[d] = static_cast<int8_t>(1 - small);
  }
}

void EliminationState::collapse(int32_t c) {
  std::vector<ChordStep> steps;
  chord_steps(c, steps);
  mark_chord_quads(steps);

  marks_.push_back(log_.size());
  sizes_valid_ = false;
  // Merge the chord's parallel edges: follow each chain of chord quads (more than one when the
  // chord touches itself) from a non-chord half-edge to the next one and pair those two.
  for (const ChordStep& s : steps)
    for (int p : {1, 3}) {
      int32_t x = opp_[he_of(s.quad, s.edge + p)];
      if (is_marked(x >> 2)) continue;  // interior of a chain: handled from its ends
      EdgeWeight w = weight_[x];
      int32_t g = s.quad, k = (s.edge + p) & 3;
      int32_t y;
      int guard = 0;
      while (true) {
        y = opp_[he_of(g, k + 2)];
        if (!is_marked(y >> 2)) break;
        const EdgeWeight& m = weight_[y];
        w.sharp += m.sharp, w.convex += m.convex, w.concave += m.concave, w.bend += m.bend;
        g = y >> 2;
        k = y & 3;
        HEXPEEL_ASSERT(++guard <= static_cast<int>(steps.size()));
      }
      if (x > y) continue;  // each chain once, from its smaller end
      const EdgeWeight& wy = weight_[y];
      w.sharp += wy.sharp, w.convex += wy.convex, w.concave += wy.concave, w.bend += wy.bend;
      set_opp(x, y);
      set_opp(y, x);
      set_weight(x, w);
      set_weight(y, w);
    }
  // Merge the ends of every crossed edge.
  for (const ChordStep& s : steps) {
    const Quad& f = surface_->quads[s.quad];
    int32_t a = find(f[s.edge & 3]), b = find(f[(s.edge + 1) & 3]);
    if (a == b) continue;
    if (uf_rank_[a] < uf_rank_[b]) std::swap(a, b);
    if (uf_rank_[a] == uf_rank_[b]) {
      log_.push_back({LogEntry::rank, a, uf_rank_[a], {}});
      ++uf_rank_[a];
    }
    log_.push_back({LogEntry::parent, b, uf_parent_[b], {}});
    uf_parent_[b] = a;
  }
  // Remove the chord's quads; shorten the chords crossing it.
  for (const ChordStep& s : steps) {
    log_.push_back({LogEntry::quad, s.quad, quad_alive_[s.quad], {}});
    quad_alive_[s.quad] = 0;
    touch_quad(s.quad);
    int32_t d = chords_->chord_of[2 * s.quad + ((s.edge + 1) & 1)];
    log_.push_back({LogEntry::chord, d, chord_len_[d], {}});
    --chord_len_[d];
    HEXPEEL_ASSERT_MSG(chord_len_[d] > 0, "a crossing chord vanished");
  }
  log_.push_back({LogEntry::chord, c, chord_len_[c], {}});
  chord_len_[c] = 0;
  alive_quads_ -= static_cast<int32_t>(steps.size());
  alive_chords_ -= 1;
}

void EliminationState::undo() {
  HEXPEEL_ASSERT(!marks_.empty());
  sizes_valid_ = false;
  size_t mark = marks_.back();
  marks_.pop_back();
  while (log_.size() > mark) {
    const LogEntry& e = log_.back();
    switch (e.kind) {
      case LogEntry::opp: opp_[e.index] = e.old_int; break;
      case LogEntry::weight:
        weight_[e.index] = e.old_weight;
        touch_quad(e.index >> 2);
        break;
      case LogEntry::parent: uf_parent_[e.index] = e.old_int; break;
      case LogEntry::rank: uf_rank_[e.index] = static_cast<int8_t>(e.old_int); break;
      case LogEntry::quad:
        quad_alive_[e.index] = static_cast<uint8_t>(e.old_int);
        touch_quad(e.index);
        ++alive_quads_;
        break;
      case LogEntry::chord:
        if (chord_len_[e.index] == 0 && e.old_int > 0) ++alive_chords_;
        chord_len_[e.index] = e.old_int;
        break;
    }
    log_.pop_back();
  }
}

QuadSurface EliminationState::current_surface(std::vector<int32_t>* quad_ids) const {
  QuadSurface out;
  std::vector<int32_t> remap(surface_->points.size(), -1);
  if (quad_ids) quad_ids->clear();
  for (int32_t q = 0; q < surface_->num_quads(); ++q) {
    if (!quad_alive_[q]) continue;
    Quad t = corners(q);
    for (int32_t& v : t) {
      if (remap[v] < 0) {
        remap[v] = static_cast<int32_t>(out.points.size());
        out.points.push_back(surface_->points[v]);
      }
      v = remap[v];
    }
    out.quads.push_back(t);
    if (quad_ids) quad_ids->push_back(q);
  }
  return out;
}

}  // namespace hexpeel
