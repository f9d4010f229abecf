// Chords (dual cycles) of a closed quad surface (paper section 2.1; Müller-Hannemann 1999).
//
// A chord is the ring of quads met by walking from a quad through opposite edges until the walk
// returns. Every quad carries two passages, one per pair of opposite edges (parity p = 0: edges
// 0 and 2, p = 1: edges 1 and 3), and the passages split into chords uniquely, so one sweep over
// the passages in (quad, parity) order finds every chord exactly once in O(number of quads).
// A chord through both passages of one quad crosses itself there (self-intersecting).
//
// Assumes: every half-edge has an opposite (validated, closed, manifold) and no quad repeats a
// corner. Guarantees: chords ordered by their first passage (quad, parity), each walked from that
// passage entering through edge p, so the result depends only on the quads' ids and corner order.
#include "hexpeel/chords.h"

#include "hexpeel/status.h"

#include <algorithm>
#include <string>

namespace hexpeel {

ChordSet find_chords(const QuadSurface& surface, const QuadAdjacency& adjacency) {
  const int32_t nq = surface.num_quads();
  HEXPEEL_ASSERT(adjacency.opposite.size() == 4 * static_cast<size_t>(nq));
  ChordSet set;
  set.chord_of.assign(2 * static_cast<size_t>(nq), -1);
  for (int32_t q0 = 0; q0 < nq; ++q0)
    for (int8_t p0 = 0; p0 < 2; ++p0) {
      if (set.chord_of[2 * q0 + p0] >= 0) continue;
      const int32_t id = static_cast<int32_t>(set.chords.size());
      Chord chord;
      int32_t q = q0;
      int8_t e = p0;
      // Each step marks its passage; the walk is a permutation of passages, so it can only
      // come back to a marked passage at the start.
      while (set.chord_of[2 * q + (e & 1)] < 0) {
        set.chord_of[2 * q + (e & 1)] = id;
        chord.steps.push_back({q, e});
        const int32_t he = adjacency.opposite[4 * q + ((e + 2) & 3)];
        HEXPEEL_ASSERT_MSG(he >= 0, "find_chords: quad " + std::to_string(q) +
                                        " has an edge without a neighbour");
        q = he >> 2;
        e = static_cast<int8_t>(he & 3);
      }
      HEXPEEL_ASSERT_MSG(q == q0 && e == p0,
                         "find_chords: walk from quad " + std::to_string(q0) + " did not close");
      for (const ChordStep& st : chord.steps)
        if (set.chord_of[2 * st.quad] == set.chord_of[2 * st.quad + 1])
          chord.crossings.push_back(st.quad);
      std::sort(chord.crossings.begin(), chord.crossings.end());
      chord.crossings.erase(std::unique(chord.crossings.begin(), chord.crossings.end()),
                            chord.crossings.end());
      chord.self_intersecting = !chord.crossings.empty();
      set.chords.push_back(std::move(chord));
    }
  return set;
}

ChordStats chord_stats(const ChordSet& chords) {
  ChordStats st;
  st.count = static_cast<int32_t>(chords.chords.size());
  if (st.count == 0) return st;
  int64_t total = 0;
  st.min_length = st.max_length = static_cast<int32_t>(chords.chords.front().steps.size());
  for (const Chord& c : chords.chords) {
    const int32_t len = static_cast<int32_t>(c.steps.size());
    st.min_length = std::min(st.min_length, len);
    st.max_length = std::max(st.max_length, len);
    total += len;
    if (c.self_intersecting) ++st.self_intersecting;
    st.self_crossings += static_cast<int32_t>(c.crossings.size());
  }
  st.mean_length = static_cast<double>(total) / st.count;
  return st;
}

}  // namespace hexpeel
