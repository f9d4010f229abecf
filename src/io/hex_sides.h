// The boundary of a hex mesh as FEA formats name it: element-side pairs, each side numbered by the
// format's own table of local faces. Internal to src/io (the Abaqus and Exodus II writers).
#pragma once

#include "hexpeel/hex_mesh.h"
#include "hexpeel/io.h"
#include "hexpeel/status.h"

#include <array>
#include <cstdint>
#include <map>
#include <vector>

namespace hexpeel::io {

/// A format's local faces of a hex: side s (0-based) has the VTK-order corners table[s]. Only the
/// set of corners matters here, not their order.
using SideTable = std::array<std::array<int, 4>, 6>;

/// One side of one hex: `side` indexes the format's SideTable (0-based).
struct HexSide {
  int32_t hex = 0;
  int32_t side = 0;
};

/// The boundary: every side whose vertex set occurs exactly once in the mesh (faces shared by two
/// hexes are interior), ordered by hex, then side. Any complete SideTable gives the same faces.
std::vector<HexSide> boundary_sides(const HexMesh& mesh, const SideTable& table);

/// The sorted, distinct vertices of `sides`.
std::vector<int32_t> side_vertices(const HexMesh& mesh, const SideTable& table,
                                   const std::vector<HexSide>& sides);

/// BoundaryPatches checked against a mesh, looked up by a face's corners.
struct PatchLookup {
  const BoundaryPatches* patches = nullptr;
  std::map<std::array<int32_t, 4>, int32_t> patch_of;  ///< sorted corners -> patch

  /// The patch of one side, -1 when it is in none.
  int32_t patch_at(const HexMesh& mesh, const SideTable& table, const HexSide& side) const;
  /// `sides` split by patch: entry k lists patch k's sides, in the order of `sides`.
  std::vector<std::vector<HexSide>> by_patch(const HexMesh& mesh, const SideTable& table,
                                             const std::vector<HexSide>& sides) const;
};

/// Checks `patches` (sizes agree, patch ids in [0, count), every face a boundary face of the
/// mesh, no face twice) and builds the lookup; the error names the first bad face.
Status make_patch_lookup(const HexMesh& mesh, const BoundaryPatches& patches, PatchLookup& out);

}  // namespace hexpeel::io
