// Helpers shared by the generator files (tests/support only; not part of the generators API).
#pragma once

#include "support/generators.h"

#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

namespace hexpeel::testing::detail {

/// Deterministic random numbers: std::mt19937_64 is specified bit for bit by the standard; the
/// mappings below are ours (std distributions are implementation-defined).
class Rng {
 public:
  explicit Rng(uint64_t seed) : engine_(seed) {}
  /// Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  /// Uniform integer in [0, n), n > 0 (tiny bias for huge n; irrelevant here).
  uint64_t below(uint64_t n) { return engine_() % n; }

 private:
  std::mt19937_64 engine_;
};

/// Faces of `mesh` used by exactly one hex, outward (kHexFaces order), in (hex, local face) order.
/// Sets `error` when a face is used by more than two hexes.
std::vector<Quad> boundary_quads(const HexMesh& mesh, std::string* error = nullptr);

/// Checks a set of polygons (`arity` corners each, flattened into `corners`) as a surface:
/// each directed edge at most once, each undirected edge in one or two polygons (two when
/// `closed`), each vertex's polygons one fan with 0 or 2 boundary edges, one component, and
/// V - E + F == `euler`. Returns "" when fine.
std::string check_polygons(const std::vector<int32_t>& corners, int arity, bool closed, int euler);

/// The complex checks of check_known_mesh without the comparison to a given surface: faces used
/// once or twice (oppositely), vertex links spheres or disks, V-E+F-H = 1, boundary a sphere.
/// Only the links of `link_vertices` are checked when given (callers that know where the mesh
/// changed), else all.
std::string check_hex_complex(const HexMesh& mesh,
                              const std::vector<int32_t>* link_vertices = nullptr);

/// A Generated built from a hex mesh: its boundary becomes the surface, vertices renumbered so the
/// boundary vertices come first (in order of first use by the boundary quads), unused vertices
/// dropped; chords walked on the surface. The mesh is not checked here.
Generated from_hex_mesh(std::string name, const HexMesh& mesh);

/// Hexes of the cells of an nx x ny x nz grid (cell (i,j,k) has index i + nx*(j + ny*k)) that are
/// `filled` (all when `filled` is empty); grid point (i,j,k) is at `position(i,j,k)`. Points of
/// unfilled cells stay (from_hex_mesh drops them).
HexMesh grid_mesh(int nx, int ny, int nz, const std::function<Vec3(int, int, int)>& position,
                  const std::vector<uint8_t>& filled = {});

}  // namespace hexpeel::testing::detail
