// A surface with its chords and edge classification, ready for an EliminationState (tests).
#pragma once

#include "hexpeel/chords.h"
#include "hexpeel/quad_surface.h"

namespace hexpeel::testing {

struct Prepared {
  QuadSurface surface;
  ChordSet chords;
  EdgeGeometry edges;
};

/// Chords and edges (sharp at `sharp_angle_deg`) of a valid surface.
inline Prepared prepare(const QuadSurface& s, double sharp_angle_deg = 60.0) {
  Prepared p{s, {}, {}};
  QuadAdjacency adj = build_adjacency(p.surface);
  p.chords = find_chords(p.surface, adj);
  p.edges = classify_edges(p.surface, adj, sharp_angle_deg);
  return p;
}

}  // namespace hexpeel::testing
