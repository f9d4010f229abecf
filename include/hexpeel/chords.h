// Chords (dual cycles) of a closed quad surface, and the sharp-edge classification that weights
// them (paper sections 2.1, 3.4, 5.1).
#pragma once

#include "hexpeel/quad_surface.h"

#include <cstdint>
#include <vector>

namespace hexpeel {

/// One passage of a chord through a quad: the chord enters quad `quad` through local edge `edge`
/// and leaves through edge (edge+2)%4. Edges edge+1 and edge+3 are parallel to the chord:
/// edge+3 is on the chord's left, edge+1 on its right.
struct ChordStep {
  int32_t quad = -1;
  int8_t edge = 0;
};

struct Chord {
  std::vector<ChordStep> steps;   ///< in walking order; the walk closes on steps[0]
  bool self_intersecting = false; ///< passes through some quad twice
  std::vector<int32_t> crossings; ///< quads it passes twice (sorted), when self-intersecting
};

struct ChordSet {
  std::vector<Chord> chords;            ///< ordered by their first (quad, edge) — deterministic
  /// chord_of[2*q + p]: the chord through quad q crossing edges p and p+2 (p = 0 or 1).
  std::vector<int32_t> chord_of;
};

/// Decomposes a closed quad surface (valid adjacency) into its chords.
ChordSet find_chords(const QuadSurface& surface, const QuadAdjacency& adjacency);

struct ChordStats {
  int32_t count = 0;
  int32_t min_length = 0, max_length = 0;
  double mean_length = 0.0;
  int32_t self_intersecting = 0;
  int32_t self_crossings = 0;  ///< quads passed twice by one chord, over all chords
};
ChordStats chord_stats(const ChordSet& chords);

/// Sharpness of one undirected edge, from the dihedral angle between its two quads.
enum class EdgeKind : int8_t { flat = 0, convex = 1, concave = 2 };

struct EdgeGeometry {
  /// kind[he] for every half-edge 4*q+k (both half-edges of an edge agree).
  std::vector<EdgeKind> kind;
  /// dihedral deviation from flat in degrees, per half-edge (0 = flat, >0 convex, <0 concave)
  std::vector<double> bend_deg;
  int32_t sharp_convex = 0, sharp_concave = 0, flat = 0;  ///< counts of undirected edges
};

/// Classifies edges: sharp when the normals' angle exceeds `sharp_angle_deg` (deviation from
/// flat), convex or concave by the sign of the bend seen from outside.
EdgeGeometry classify_edges(const QuadSurface& surface, const QuadAdjacency& adjacency,
                            double sharp_angle_deg = 60.0);

/// The surface cut along its sharp edges (convex or concave in `edges`) into patches, as a CAD
/// model's faces: patch[q] for every quad, numbered 0.. in the order of each patch's smallest
/// quad id. Returns the patch count in `count`.
std::vector<int32_t> sharp_patches(const QuadSurface& surface, const QuadAdjacency& adjacency,
                                   const EdgeGeometry& edges, int32_t& count);

}  // namespace hexpeel
