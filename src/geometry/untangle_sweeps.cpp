// Local max-min and mean sweeps: pattern search of one vertex at a time (untangle_problem.h,
// UntangleParams::local_sweeps).
#include "geometry/untangle_problem.h"

#include "hexpeel/quality.h"
#include "quality/quality_internal.h"

namespace hexpeel::untangle_detail {

int64_t local_max_min(const Problem& prob, std::vector<Vec3>& pts, const UntangleParams& params,
                      bool max_min_sweeps, bool mean_sweeps) {
  const std::vector<Hex>& hexes = prob.hexes;
  const int32_t nh = static_cast<int32_t>(hexes.size());
  const int32_t np = static_cast<int32_t>(pts.size());
  if (nh == 0 || params.local_sweeps <= 0 || params.local_hexes <= 0) return 0;
  // The hexes of free point v: slots inc_slot[i] / 8 for i in the range of its unknown.
  auto first = [&](int32_t v) { return prob.inc_start[prob.free_index[v]]; };
  auto last = [&](int32_t v) { return prob.inc_start[prob.free_index[v] + 1]; };
  auto hex_sj = [&](int32_t h) {
    std::array<Vec3, 8> c;
    for (int k = 0; k < 8; ++k) c[k] = pts[hexes[h][k]];
    return scaled_jacobian(c);
  };
  // While v moves, only v's point of each of its hexes changes, and only 5 of a hex's 9 scaled
  // Jacobian terms: the centre, v's corner k and the corners of k's 3 edge neighbours. A search
  // keeps, per hex of v, the hex's points (c[k] is v's, updated per trial) and the minimum of the
  // other 4 terms (a degenerate term is -2, below any value, so the minimum keeps it and equals
  // scaled_jacobian exactly, given 8 distinct points per hex, as reconstruction builds).
  struct HexOfVertex {
    std::array<Vec3, 8> c;
    int k;
    double rest;
  };
  auto hexes_of = [&](int32_t v, std::vector<HexOfVertex>& out) {
    out.resize(last(v) - first(v));
    for (int32_t i = first(v); i < last(v); ++i) {
      HexOfVertex& h = out[i - first(v)];
      h.k = prob.inc_slot[i] % 8;
      for (int j = 0; j < 8; ++j) h.c[j] = pts[hexes[prob.inc_slot[i] / 8][j]];
      const auto& nb = kHexCornerFrames[h.k];
      h.rest = std::numeric_limits<double>::infinity();
      for (int corner = 0; corner < 8; ++corner)
        if (corner != h.k && corner != nb[0] && corner != nb[1] && corner != nb[2])
          h.rest = std::min(h.rest, scaled_jacobian_term(h.c, 1 + corner));
    }
  };
  // The scaled Jacobian of hex h of v with v at p.
  auto hex_value = [&](HexOfVertex& h, const Vec3& p) {
    h.c[h.k] = p;
    const auto& nb = kHexCornerFrames[h.k];
    double q = h.rest;
    for (int term : {0, 1 + h.k, 1 + nb[0], 1 + nb[1], 1 + nb[2]})
      q = std::min(q, scaled_jacobian_term(h.c, term));
    return q == std::numeric_limits<double>::infinity() ? kDegenerateScaledJacobian : q;  // all NaN
  };
  // (min, mean) of the scaled Jacobians of v's hexes with v at p, and the hex of the minimum. A
  // trial whose minimum drops below `floor` is rejected whatever its mean, so the evaluation
  // stops at the first hex below it (then only `min < floor` is meaningful); hex `worst` (the
  // current minimum's, the likeliest to drop) is tried first. The mean sums in hex order.
  struct VertexQuality {
    double min, mean;
    int worst;
  };
  auto vertex_quality = [&](const Vec3& p, std::vector<HexOfVertex>& hs, int worst, double floor) {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    const double q_worst = worst >= 0 ? hex_value(hs[worst], p) : kInf;
    if (q_worst < floor) return VertexQuality{q_worst, 0.0, worst};
    VertexQuality out{kInf, 0.0, -1};
    double sum = 0.0;
    for (int i = 0; i < static_cast<int>(hs.size()); ++i) {
      const double q = i == worst ? q_worst : hex_value(hs[i], p);
      if (q < floor) return VertexQuality{q, 0.0, i};
      if (q < out.min) out.min = q, out.worst = i;
      sum += q;
    }
    out.mean = sum / std::max<size_t>(1, hs.size());
    return out;
  };
  // A step must not lower the minimum and must raise minimum + w * mean: w = local_mean_weight
  // for the worst hexes' vertices; the other vertices' steps are for the mean alone (kMeanOnly:
  // scoring their local minimum too lowered the mean).
  constexpr double kMeanOnly = -1.0;
  auto score = [&](const VertexQuality& q, double w) {
    return w == kMeanOnly ? q.mean : q.min + w * q.mean;
  };
  static const std::array<Vec3, 14> dirs = [] {
    std::array<Vec3, 14> d;
    int n = 0;
    for (int a = 0; a < 3; ++a)
      for (double sgn : {1.0, -1.0}) d[n++] = sgn * Vec3::Unit(a);
    for (int m = 0; m < 8; ++m)
      d[n++] = Vec3(m & 1 ? 1 : -1, m & 2 ? 1 : -1, m & 4 ? 1 : -1) / std::sqrt(3.0);
    return d;
  }();
  // The pattern search of one vertex, down to steps of stop times its scale; returns its moves.
  auto search = [&](int32_t v, double stop, double w) {
    double len = 0.0;
    int count = 0;
    for (int32_t i = first(v); i < last(v); ++i)
      for (int32_t u : hexes[prob.inc_slot[i] / 8])
        if (u != v) len += (pts[u] - pts[v]).norm(), ++count;
    const double l = count > 0 ? len / count : 0.0;
    std::vector<HexOfVertex> hs;
    hexes_of(v, hs);
    VertexQuality cur = vertex_quality(pts[v], hs, -1, -std::numeric_limits<double>::infinity());
    // A step may take any hex of v down to v's minimum: for the mean alone, not when that
    // minimum is a hex <= 0 (a forced corner, say), which would let the others follow it.
    if (w == kMeanOnly && !(cur.min > 0.0)) return 0;
    int32_t moved = 0;
    double step = 0.1 * l;
    for (int it = 0; it < 200 && step > stop * l; ++it) {
      const Vec3 old = pts[v];
      int best = -1;
      VertexQuality best_q = cur;
      for (int d = 0; d < 14; ++d) {
        const VertexQuality q = vertex_quality(old + step * dirs[d], hs, cur.worst, cur.min);
        if (q.min >= cur.min && score(q, w) > score(best_q, w)) best_q = q, best = d;
      }
      if (best >= 0) {
        pts[v] = old + step * dirs[best];
        cur = best_q;
        ++moved;
      } else {
        step *= 0.5;
      }
    }
    return moved;
  };
  std::vector<double> sj(nh);
  // The scaled Jacobians of all hexes into sj; their minimum and mean (summed in hex order: the
  // same for any thread count).
  auto measure = [&](double& sj_min, double& sj_mean) {
    tbb::parallel_for(tbb::blocked_range<int32_t>(0, nh, 512),
                      [&](const tbb::blocked_range<int32_t>& r) {
                        for (int32_t h = r.begin(); h != r.end(); ++h) sj[h] = hex_sj(h);
                      });
    sj_min = *std::min_element(sj.begin(), sj.end());
    sj_mean = std::accumulate(sj.begin(), sj.end(), 0.0) / nh;
  };
  // The free vertices without skip[v], coloured greedily in id order so that no two of a colour
  // share a hex, sorted by colour (stable); color[v] receives v's colour.
  std::vector<int32_t> color(np, -1), moved;
  std::vector<uint8_t> used;
  auto colour = [&](const std::vector<uint8_t>& skip) {
    std::vector<int32_t> verts;
    std::fill(color.begin(), color.end(), -1);
    int32_t colors = 0;
    for (int32_t v = 0; v < np; ++v) {
      if (prob.free_index[v] < 0 || skip[v]) continue;
      used.assign(colors + 1, 0);
      for (int32_t j = first(v); j < last(v); ++j)
        for (int32_t w : hexes[prob.inc_slot[j] / 8])
          if (color[w] >= 0) used[color[w]] = 1;
      int32_t c = 0;
      while (used[c]) ++c;
      color[v] = c;
      colors = std::max(colors, c + 1);
      verts.push_back(v);
    }
    std::stable_sort(verts.begin(), verts.end(),
                     [&](int32_t a, int32_t b) { return color[a] < color[b]; });
    return verts;
  };
  // Searches the vertices of `verts` group after group (group(i) is verts[i]'s; each group a
  // run of equal values, the runs in order), the vertices of one group in parallel: no two of a
  // group may share a hex, so each reads only hexes no other one moves. Returns the moves.
  auto search_groups = [&](const std::vector<int32_t>& verts, auto&& group, double stop, double w) {
    moved.assign(verts.size(), 0);
    for (size_t b = 0; b < verts.size();) {
      size_t e = b;
      while (e < verts.size() && group(e) == group(b)) ++e;
      tbb::parallel_for(tbb::blocked_range<size_t>(b, e, 4),
                        [&](const tbb::blocked_range<size_t>& r) {
                          for (size_t i = r.begin(); i != r.end(); ++i)
                            moved[i] = search(verts[i], stop, w);
                        });
      b = e;
    }
    return std::accumulate(moved.begin(), moved.end(), int64_t{0});
  };
  // Searches the vertices of `verts` (sorted by colour) for the mean alone, down to steps of
  // `stop` times their scale, colour after colour.
  auto sweep_colours = [&](const std::vector<int32_t>& verts, double stop) {
    return search_groups(verts, [&](size_t i) { return color[verts[i]]; }, stop, kMeanOnly);
  };
  // Searches the vertices of `verts` in their order, as one after the other would, but in
  // parallel where that gives the same result: a search reads and moves only points of its
  // vertex's hexes, so a vertex that shares no hex with an earlier one still to run may run
  // now. A vertex's level is one above the highest level of the earlier vertices it shares a
  // hex with (0 when there are none), so two of one level share no hex; the levels run in
  // order. Returns the moves.
  std::vector<int32_t> hex_level(nh), level, by_level;
  auto search_in_order = [&](const std::vector<int32_t>& verts, double stop, double w) {
    const size_t n = verts.size();
    std::fill(hex_level.begin(), hex_level.end(), -1);
    level.resize(n);
    for (size_t j = 0; j < n; ++j) {
      int32_t l = 0;
      for (int32_t i = first(verts[j]); i < last(verts[j]); ++i)
        l = std::max(l, hex_level[prob.inc_slot[i] / 8] + 1);
      level[j] = l;
      for (int32_t i = first(verts[j]); i < last(verts[j]); ++i) hex_level[prob.inc_slot[i] / 8] = l;
    }
    by_level.resize(n);
    std::iota(by_level.begin(), by_level.end(), 0);
    std::stable_sort(by_level.begin(), by_level.end(),
                     [&](int32_t a, int32_t b) { return level[a] < level[b]; });
    std::vector<int32_t> ordered(n);
    for (size_t i = 0; i < n; ++i) ordered[i] = verts[by_level[i]];
    return search_groups(ordered, [&](size_t i) { return level[by_level[i]]; }, stop, w);
  };
  std::vector<uint8_t> in_worst(np, 0);
  int64_t moves = 0;
  double last_min = 0.0, last_mean = 0.0;
  const int max_sweeps = std::max(params.local_sweeps, params.local_sweeps_max);
  for (int sweep = 0; max_min_sweeps && sweep < max_sweeps; ++sweep) {
    double sj_min, sj_mean;
    measure(sj_min, sj_mean);
    if (sweep >= params.local_sweeps && sj_min - last_min < params.local_sweep_min_gain &&
        sj_mean - last_mean < params.local_sweep_mean_gain)
      break;
    last_min = sj_min, last_mean = sj_mean;
    std::vector<int32_t> order(nh);
    std::iota(order.begin(), order.end(), 0);
    const int32_t k = std::min(nh, params.local_hexes);
    std::partial_sort(order.begin(), order.begin() + k, order.end(), [&](int32_t a, int32_t b) {
      return sj[a] != sj[b] ? sj[a] < sj[b] : a < b;
    });
    // 1. The free vertices of the k worst hexes, worst hex first, one after the other: each sees
    // the moves before it (moving them in parallel lowered the minimum on pierrot and screw2);
    // search_in_order runs the independent ones side by side, with the same result.
    std::vector<int32_t> verts;
    std::fill(in_worst.begin(), in_worst.end(), 0);
    for (int32_t i = 0; i < k; ++i)
      for (int32_t v : hexes[order[i]])
        if (prob.free_index[v] >= 0 && !in_worst[v]) in_worst[v] = 1, verts.push_back(v);
    int64_t sweep_moves = 0;
    sweep_moves += search_in_order(verts, 1e-3, params.local_mean_weight);
    // 2. With local_all, every other free vertex, by colours.
    if (params.local_all) sweep_moves += sweep_colours(colour(in_worst), params.local_all_stop);
    moves += sweep_moves;
    if (sweep_moves == 0) break;
  }
  // 3. The mean sweeps: every free vertex, by colours, with finer steps, while the mean rises.
  // Their steps never lower a vertex's own minimum, so the minimum reached above stays.
  if (mean_sweeps && params.local_all && params.local_polish_stop > 0.0) {
    const std::vector<int32_t> verts = colour(std::vector<uint8_t>(np, 0));
    measure(last_min, last_mean);
    for (int sweep = 0; sweep < max_sweeps; ++sweep) {
      const int64_t sweep_moves = sweep_colours(verts, params.local_polish_stop);
      moves += sweep_moves;
      double sj_min, sj_mean;
      measure(sj_min, sj_mean);
      if (sweep_moves == 0 || sj_mean - last_mean < params.local_sweep_mean_gain) break;
      last_mean = sj_mean;
    }
  }
  return moves;
}

}  // namespace hexpeel::untangle_detail
