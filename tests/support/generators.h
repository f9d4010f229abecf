// Generators of valid genus-0 closed quad surfaces for tests and benchmarks, each with what the
// generator knows about it (the chord count and lengths, the hex count of one valid answer).
#pragma once

#include "hexpeel/hex_mesh.h"
#include "hexpeel/quad_surface.h"

#include <cstdint>
#include <string>
#include <vector>

namespace hexpeel::testing {

/// A generated surface with what its generator knows.
struct Generated {
  std::string name;
  QuadSurface surface;      ///< outward oriented
  HexMesh known_mesh;       ///< a valid hex mesh whose boundary is `surface` (empty if unknown)
  int32_t chords = -1;      ///< number of chords, -1 if unknown
  std::vector<int32_t> chord_lengths;  ///< sorted, empty if unknown
};

/// Boundary of an nx × ny × nz grid of unit-size cells over [0,nx]x[0,ny]x[0,nz] scaled by `size`.
Generated cube(int nx, int ny, int nz, double size = 1.0);
/// Cubed sphere: the boundary of cube(n,n,n) projected to the unit sphere (6 n^2 quads).
Generated cubed_sphere(int n);
/// Union of unit voxels given as a boolean grid (x fastest), each voxel split m×m×m. The voxel
/// set must be face-connected and its boundary a sphere (no tunnels/cavities, no edge- or
/// vertex-only contacts); `voxel_solid` checks and returns an empty surface otherwise.
Generated voxel_solid(int nx, int ny, int nz, const std::vector<uint8_t>& filled, int m = 1,
                      const std::string& name = "voxels");
/// A random voxel solid grown from a seed cell (at most `cells` voxels inside an n^3 box), kept
/// only when its boundary is a sphere; deterministic for a seed.
Generated random_voxel_solid(uint64_t seed, int n, int cells, int m = 1);
/// Named concave shapes: "L", "U", "T", "pocket", "notch", "stairs", "steps", each split m.
Generated named_solid(const std::string& shape, int m = 1);
/// Random displacement of every vertex by up to `amount` times the local edge length, along the
/// surface tangent plane so the surface stays valid. Deterministic for a seed.
Generated perturbed(const Generated& g, uint64_t seed, double amount = 0.1);
/// Every quad split into 2x2 (chord count doubles, lengths double).
Generated refined(const Generated& g);

}  // namespace hexpeel::testing
