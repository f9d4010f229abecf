// Chord ranking and side choice: Müller-Hannemann's weights (paper 3.4) and the rules of Kremer,
// Bommes, Lim, Kobbelt (IMR 2013) sections 4.1, 4.2, 5.1, 5.2 and 5.4.
//
// Original method: priority grows with the larger side weight (sharp parallel edges per chord
// length); flat chords (crossing no sharp edge) only when nothing else is feasible; ties by
// shorter chord, then smaller id. Side: the heavier usable side; equal weights -> the side with
// fewer quads (fewer hexes), then left.
//
// Kremer method: key[0] is a tier, the sum of postponements (smaller first):
//   concave chord (5.1-5.2)                                   0   (key[1] = -concavity weight)
//   convex chord                                              1   (key[1] = -sharp weight)
//   + convex on both sides (5.2, weight >= both_convex_min)   2
//   + zero-volume configuration (4.1)                         4
//   + waits for an enclosed chord (4.2, 5.4)                  8
//   + flat (crosses no sharp edge; never concave)            16
// A chord is concave on side s when its concavity weight on s is positive and at least
// concave_min, s is usable, the
// side region is flat (5.4 false positives: no sharp edge between two of its quads) and encloses
// no non-flat chord (5.4 "enclosed concave cycles"); a concave candidate failing only the last
// test is rated as a convex chord that waits. 4.2 prefers a usable side that encloses no whole
// chord; a chord enclosing one on every usable side waits.
//
// Zero volume (4.1): the paper measures dihedral angles outside the solid (3.4), i.e. 180 + bend
// with our signed bends (>0 convex). Two successive crossed edges whose outside angles sum to
// about 180 degrees (bend_i + bend_i+1 ~ -180, e.g. the two concave edges of a one-quad-wide
// groove floor) make a layer with a zero-volume hex. Bends of merged edges add (3.4).
//
// quick() uses only the chord's own weights and crossed edges: it is optimistic about concavity
// (tier 0 whenever a concavity weight is positive) and ignores the region rules, which can only
// raise the tier, so it stays a lower bound of full(). Everything is deterministic: keys end
// with the chord id, sides tie-break on region size, then left.
#include "hexpeel/order.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

namespace hexpeel {

std::string_view to_string(Method method) {
  switch (method) {
    case Method::original: return "original";
    case Method::kremer: return "kremer";
  }
  return "?";
}

std::string_view to_string(SideRule rule) {
  switch (rule) {
    case SideRule::heavier: return "heavier";
    case SideRule::cost: return "cost";
  }
  return "?";
}

namespace {

constexpr double kTierConvex = 1, kTierBothConvex = 2, kTierZeroVolume = 4, kTierWaits = 8,
                 kTierFlat = 16;

/// 4.1: two successive crossed edges of chord c whose outside dihedral angles sum to ~180 deg.
bool has_zero_volume(const EliminationState& state, int32_t c, double tolerance_deg) {
  // Walk the input passages, skipping eliminated quads (no allocation: called for every chord).
  const std::vector<ChordStep>& steps = state.chord_set().chords[c].steps;
  double first = 0.0, prev = 0.0;
  bool any = false;
  for (const ChordStep& s : steps) {
    if (!state.quad_alive(s.quad)) continue;
    const double b = state.edge_weight(4 * s.quad + s.edge).bend;
    if (!any) first = b, any = true;
    else if (std::abs(prev + b + 180.0) <= tolerance_deg) return true;
    prev = b;
  }
  return any && state.chord_length(c) > 1 && std::abs(prev + first + 180.0) <= tolerance_deg;
}

/// Whole alive chords enclosed on each side of chord c (any / crossing a sharp edge).
struct Enclosed {
  std::array<bool, 2> chord{};    ///< some alive chord other than c lies entirely on that side
  std::array<bool, 2> nonflat{};  ///< ... and crosses a sharp edge
};

Enclosed enclosed_chords(const EliminationState& state, int32_t c) {
  thread_local std::vector<int8_t> where;
  state.chord_sides(c, where);
  Enclosed e;
  for (int32_t d = 0; d < static_cast<int32_t>(where.size()); ++d) {
    if (where[d] < 0) continue;
    e.chord[where[d]] = true;
    if (!e.nonflat[where[d]] && state.weights(d).crossing_sharp > 0) e.nonflat[where[d]] = true;
  }
  return e;
}

/// 5.4 false positives: no sharp edge between two quads of side s of chord c.
bool flat_inside(const EliminationState& state, int32_t c, int side) {
  std::vector<int32_t> region;
  state.side_region(c, side, region);
  for (int32_t q : region)
    for (int k = 0; k < 4; ++k) {
      const int32_t he = 4 * q + k;
      if (state.edge_weight(he).sharp > 0 &&
          std::binary_search(region.begin(), region.end(), state.opposite(he) >> 2))
        return false;
    }
  return true;
}

/// The original side rule among `sides`: heavier sharp weight; ties -> fewer quads, then left.
int heavier_side(const EliminationState& state, int32_t chord, const ChordWeights& w,
                 std::array<bool, 2> sides, const std::array<int32_t, 2>& sizes) {
  if (sides[0] && sides[1] && w.sharp[0] == w.sharp[1]) {
    const int32_t s0 = sizes[0] >= 0 ? sizes[0] : state.side_size(chord, 0);
    const int32_t s1 = sizes[1] >= 0 ? sizes[1] : state.side_size(chord, 1);
    return s1 < s0 ? 1 : 0;
  }
  if (sides[0] && sides[1]) return w.sharp[0] > w.sharp[1] ? 0 : 1;
  return sides[0] ? 0 : 1;
}

/// The side a convex move takes under SideRule::cost, and that side's size.
std::pair<int, int32_t> cost_side(const EliminationState& state, int32_t chord, const ChordWeights& w,
                                  std::array<bool, 2> sides, std::array<int32_t, 2> sizes,
                                  const OrderParams& p) {
  for (int s = 0; s < 2; ++s)
    if (sides[s] && sizes[s] < 0) sizes[s] = state.side_size(chord, s);
  if (!(sides[0] && sides[1])) {
    int s = sides[0] ? 0 : 1;
    return {s, sizes[s]};
  }
  const int small = sizes[1] < sizes[0] ? 1 : 0;
  const int other = 1 - small;
  const int s = w.sharp[other] - w.sharp[small] >= p.side_threshold ? other : small;
  return {s, sizes[s]};
}

/// The key's weight entry for a convex move on `side`: minus its sharp weight, plus the size term
/// of SideRule::cost (never below the quick key's -max weight, as quick() requires).
double side_key(const EliminationState& state, const ChordWeights& w, int side, int32_t size,
                const OrderParams& p) {
  double k = -w.sharp[side];
  if (p.side_rule == SideRule::cost)
    k += p.size_weight * static_cast<double>(size) / std::max<int32_t>(1, state.alive_quads());
  return k;
}

/// A lower bound of full()'s weight entry for a convex move whatever sides are usable: the
/// smallest side_key over both sides (side sizes are O(1) once computed for the state).
double quick_weight_key(const EliminationState& state, int32_t chord, const ChordWeights& w,
                        const OrderParams& p) {
  if (p.side_rule != SideRule::cost) return -std::max(w.sharp[0], w.sharp[1]);
  return std::min(side_key(state, w, 0, state.side_size(chord, 0), p),
                  side_key(state, w, 1, state.side_size(chord, 1), p));
}

/// Tier of a convex move (kremer): sets m.zero_volume; m.flat and m.waits must be set.
double convex_tier(const EliminationState& state, const ChordWeights& w, const OrderParams& p,
                   Move& m) {
  m.zero_volume = p.zero_volume && has_zero_volume(state, m.chord, p.zero_volume_tolerance_deg);
  double tier = kTierConvex;
  if (p.concave && w.convex[0] >= p.both_convex_min && w.convex[1] >= p.both_convex_min)
    tier += kTierBothConvex;
  if (m.zero_volume) tier += kTierZeroVolume;
  if (m.waits) tier += kTierWaits;
  if (m.flat) tier += kTierFlat;
  return tier;
}

}  // namespace

Move OrderPolicy::quick(const EliminationState& state, int32_t chord) const {
  ChordWeights w = state.weights(chord);
  Move m;
  m.chord = chord;
  m.flat = w.crossing_sharp == 0;
  if (params_.method == Method::original) {
    m.key = {m.flat ? 1.0 : 0.0, quick_weight_key(state, chord, w, params_),
             static_cast<double>(w.length), static_cast<double>(chord)};
    return m;
  }
  const double concavity = std::max(w.concave[0], w.concave[1]);
  if (params_.concave && !m.flat && concavity > 0 && concavity >= params_.concave_min) {
    m.key = {0.0, -concavity, static_cast<double>(w.length), static_cast<double>(chord)};
    return m;
  }
  const double tier = convex_tier(state, w, params_, m);
  m.key = {tier, quick_weight_key(state, chord, w, params_), static_cast<double>(w.length),
           static_cast<double>(chord)};
  return m;
}

Move OrderPolicy::full(const EliminationState& state, int32_t chord, std::array<bool, 2> sides) const {
  ChordWeights w = state.weights(chord);
  Move m;
  m.chord = chord;
  m.flat = w.crossing_sharp == 0;
  if (params_.method == Method::original) {
    double best = -1.0;
    for (int s = 0; s < 2; ++s)
      if (sides[s]) best = std::max(best, w.sharp[s]);
    m.key = {m.flat ? 1.0 : 0.0, -best, static_cast<double>(w.length), static_cast<double>(chord)};
    m.side = static_cast<int8_t>(heavier_side(state, chord, w, sides, {-1, -1}));
    if (params_.side_rule == SideRule::cost) {
      auto [side, size] = cost_side(state, chord, w, sides, {-1, -1}, params_);
      m.side = static_cast<int8_t>(side);
      m.key[1] = side_key(state, w, side, size, params_);
    }
    return m;
  }

  std::optional<Enclosed> enc;
  auto enclosed_of = [&]() -> const Enclosed& {
    if (!enc) enc = enclosed_chords(state, chord);
    return *enc;
  };
  bool concave_waits = false;
  if (params_.concave && !m.flat) {
    // Concave sides, heavier concavity first (ties: left first).
    int order[2] = {0, 1};
    if (w.concave[1] > w.concave[0]) std::swap(order[0], order[1]);
    for (int s : order) {
      if (!sides[s] || w.concave[s] <= 0 || w.concave[s] < params_.concave_min) continue;
      if (params_.false_positive && !flat_inside(state, chord, s)) continue;
      if (params_.concave_waits_for_enclosed && enclosed_of().nonflat[s]) {
        concave_waits = true;
        continue;
      }
      m.concave = true;
      m.side = static_cast<int8_t>(s);
      m.key = {0.0, -w.concave[s], static_cast<double>(w.length), static_cast<double>(chord)};
      return m;
    }
  }

  // Convex: prefer usable sides that enclose no whole chord (4.2).
  std::array<bool, 2> pick = sides;
  if (params_.enclosed) {
    std::array<bool, 2> open{};
    for (int s = 0; s < 2; ++s) open[s] = sides[s] && !enclosed_of().chord[s];
    if (open[0] || open[1]) pick = open;
    else m.waits = true;
  }
  if (concave_waits) m.waits = true;
  const std::array<int32_t, 2> sizes{-1, -1};
  int side;
  double weight_key;
  if (params_.side_rule == SideRule::cost) {
    auto [s, size] = cost_side(state, chord, w, pick, sizes, params_);
    side = s;
    weight_key = side_key(state, w, s, size, params_);
  } else {
    side = heavier_side(state, chord, w, pick, sizes);
    weight_key = -w.sharp[side];
  }
  m.side = static_cast<int8_t>(side);
  const double tier = convex_tier(state, w, params_, m);
  m.key = {tier, weight_key, static_cast<double>(w.length), static_cast<double>(chord)};
  return m;
}

}  // namespace hexpeel
