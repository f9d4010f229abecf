// Chord ranking and side choice (paper 3.4).
//
// Original method: priority grows with the larger side weight (sharp parallel edges per chord
// length); flat chords (crossing no sharp edge) only when nothing else is feasible; ties by
// shorter chord, then smaller id. Side: the heavier usable side; equal weights -> the side with
// fewer quads (fewer hexes), then left.
#include "hexpeel/order.h"

#include <algorithm>

namespace hexpeel {

Move OrderPolicy::quick(const EliminationState& state, int32_t chord) const {
  ChordWeights w = state.weights(chord);
  Move m;
  m.chord = chord;
  m.flat = w.crossing_sharp == 0;
  m.key = {m.flat ? 1.0 : 0.0, -std::max(w.sharp[0], w.sharp[1]), static_cast<double>(w.length),
           static_cast<double>(chord)};
  return m;
}

Move OrderPolicy::full(const EliminationState& state, int32_t chord, std::array<bool, 2> sides) const {
  ChordWeights w = state.weights(chord);
  Move m;
  m.chord = chord;
  m.flat = w.crossing_sharp == 0;
  double best = -1.0;
  for (int s = 0; s < 2; ++s)
    if (sides[s]) best = std::max(best, w.sharp[s]);
  m.key = {m.flat ? 1.0 : 0.0, -best, static_cast<double>(w.length), static_cast<double>(chord)};
  if (sides[0] && sides[1] && w.sharp[0] == w.sharp[1]) {
    m.side = state.side_size(chord, 1) < state.side_size(chord, 0) ? 1 : 0;
  } else if (sides[0] && sides[1]) {
    m.side = w.sharp[0] > w.sharp[1] ? 0 : 1;
  } else {
    m.side = sides[0] ? 0 : 1;
  }
  return m;
}

}  // namespace hexpeel
