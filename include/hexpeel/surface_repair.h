// Surface repair (opt-in, `hexpeel mesh --repair-surface`): re-quadrangulates a closed quad
// surface that dual cycle elimination cannot take as it is (a chord that crosses itself, an odd
// number of quads) into one it can. Every input vertex keeps its position and id; the new
// vertices lie on the input quads (their bilinear patches). Every input quad is refined:
//  - split into four (edge midpoints and its centre): the chords stay as they were, doubled;
//  - or split into six (two triangles along the shorter diagonal, each into three quads):
//    there the chords turn around the vertices instead of crossing the quad.
// Every edge is halved by both, so any mix is conforming and the count is always even. The
// quads split into six start as the quads where a chord crosses itself and grow (by the parents
// of the quads where a chord of the refined surface still crosses itself, then by their vertex
// neighbours) until every chord of the refined surface is simple. A surface that only has an odd
// count is split into four everywhere.
#pragma once

#include "hexpeel/quad_surface.h"
#include "hexpeel/status.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <vector>

namespace hexpeel {

struct SurfaceRepairStats {
  bool applied = false;
  int32_t input_quads = 0, output_quads = 0;
  int32_t input_self_crossings = 0;  ///< quads an input chord passes twice
  bool input_odd = false;
  std::vector<int32_t> six_split;    ///< input quads split into six (sorted); the rest into four
  int32_t rounds = 0;                ///< refinements tried until every chord was simple
  int32_t output_chords = 0;
};

struct SurfaceRepair {
  Status status;         ///< ok, or why no repaired surface was found
  QuadSurface surface;   ///< the repaired surface: the input's vertices first, same ids
  /// parent[q]: the input quad that repaired quad q refines
  std::vector<int32_t> parent;
  SurfaceRepairStats stats;
};

/// The diagonal a six-split cuts quad q on: 0 (corners 0-2) or 1 (1-3), the shorter one (0 on
/// a tie). refine_surface and the fill through tetrahedra (tet_fill.h) both follow it.
int six_split_diagonal(const QuadSurface& surface, int32_t q);

/// Refines `surface` (closed, edge-manifold, consistently oriented): the quads flagged in
/// `six` are split into six, the others into four. `parent` receives the input quad of each
/// output quad.
QuadSurface refine_surface(const QuadSurface& surface, const std::vector<char>& six,
                           std::vector<int32_t>& parent);

/// Repairs `surface` as described above; with `six_everywhere`, every quad is split into six
/// at once (all chords then go around the input vertices). Deterministic.
SurfaceRepair repair_surface(const QuadSurface& surface, bool six_everywhere = false);

nlohmann::json to_json(const SurfaceRepairStats& stats);

}  // namespace hexpeel
