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

/// Boundary of an nx × ny × nz grid of unit-size cells over [0,nx]x[0,ny]x[0,nz] scaled by `size`
/// (cube(n,n,n,1.0/n) is the shared cube_nN). known_mesh = the grid; chords: nx rings of length
/// 2(ny+nz), ny of 2(nx+nz), nz of 2(nx+ny).
Generated cube(int nx, int ny, int nz, double size = 1.0);
/// Cubed sphere: the boundary of cube(n,n,n) centred at the origin, projected to the unit sphere
/// (6 n^2 quads). known_mesh: the grid with each cube shell max|p_i| = r mapped radially onto the
/// sphere of radius r (all hexes positive); chords as cube(n,n,n).
Generated cubed_sphere(int n);
/// Union of unit voxels given as a boolean grid (x fastest), each voxel split m×m×m. The voxel
/// set must be face-connected and its boundary a sphere (no tunnels/cavities, no edge- or
/// vertex-only contacts); `voxel_solid` checks and returns an empty surface otherwise. Voxel
/// (i,j,k) is [i,i+1]x[j,j+1]x[k,k+1]; the result is named `name` + "_m<m>".
Generated voxel_solid(int nx, int ny, int nz, const std::vector<uint8_t>& filled, int m = 1,
                      const std::string& name = "voxels");
/// A random voxel solid grown from the centre cell of an n^3 box by random face neighbours (at most
/// `cells` voxels; fewer when no neighbour can be added), each addition kept only when the
/// boundary stays a sphere; deterministic for a seed (std::mt19937_64 with our own mappings).
Generated random_voxel_solid(uint64_t seed, int n, int cells, int m = 1);
/// Named voxel shapes, each voxel split m×m×m, named "vox_<canonical>_m<m>" as the shared files:
///   "L"  (= "L3")           3 voxels: (0,0,0), (1,0,0), (0,1,0)
///   "Lblock"                10 voxels: an L of 5 columns (x=0, y<3 and y=0, x<3), 2 high
///   "U"  (= "U3x3x1")       7 voxels: 3x3x1 minus (1,1) and (1,2)
///   "T"  (= "T4")           4 voxels: a row of 3 along x at y=1 plus (1,0)
///   "pocket" (= "pocket3x3x2") 17 voxels: 3x3x2 minus the top centre (1,1,1)
///   "notch"  (= "notch3x3x3")  24 voxels: 3x3x3 minus the row (2,y,2) along an edge
///   "stairs" (= "stairs3")  6 voxels: columns of height 3,2,1 along x, one voxel deep
///   "steps"  (= "steps3")   14 voxels: height 3 - max(x,y) over a 3x3 footprint (corner stairs)
/// An unknown shape gives an empty Generated.
Generated named_solid(const std::string& shape, int m = 1);
/// Random displacement of every surface vertex by up to `amount` times its shortest incident edge,
/// in its tangent plane (normal = sum of the incident quads' normals); known_mesh's boundary
/// vertices move identically, its interior ones stay. Deterministic for a seed. For large amounts
/// (say > 0.3) hexes of known_mesh next to the boundary may no longer all be positive.
Generated perturbed(const Generated& g, uint64_t seed, double amount = 0.1);
/// Every quad split into 2x2 (new vertices at edge midpoints and quad centroids) and every hex of
/// known_mesh into 2x2x2, ids shared so the boundary still matches (chord count doubles, lengths
/// double).
Generated refined(const Generated& g);

// ---- Additions (beyond the original interface) ------------------------------------------------

/// Equiangular cubed sphere (the family of the shared csphere_nK files): like cubed_sphere(n), but
/// each cube face is warped by tan(pi/4 t) before projection, which evens out the quad sizes.
Generated cubed_sphere_equiangular(int n);
/// Random pillowing (Mitchell & Tautges 1995): grows a random face-connected set S of at most
/// `fraction` of g.known_mesh's hexes and inserts one hex per face shared by S and a hex outside S
/// (S's faces on the boundary get none). Where S reaches the boundary the new sheet meets the
/// surface, so the surface changes (it gains a ring of quads and a chord); the returned surface
/// is the boundary of the new mesh and known_mesh.num_hexes() is one valid answer. Each growth
/// step is kept only when the new mesh is a 3-ball complex with a sphere boundary and has no more
/// non-positive hexes than g.known_mesh (so an all-positive input gives an all-positive output);
/// S stays smaller than asked when growth keeps failing. Returns g (renamed) when g has fewer
/// than two hexes.
Generated pillowed(const Generated& g, uint64_t seed, double fraction = 0.3);
/// The surface of perturbed(g, seed, amount) (identical, vertex for vertex); in addition every
/// interior vertex of known_mesh moves by up to `amount` times its shortest incident hex edge, in
/// any direction, so the known mesh is no longer an ideal grid.
Generated jittered(const Generated& g, uint64_t seed, double amount = 0.1);

/// 20 quads, 22 vertices, 6 chords, none of which can be eliminated (collapsing any would leave
/// a vertex of valence 2 or an edge with other than two quads): the surface a real surface's
/// elimination stopped at (a genus-0 cut of a published hex mesh), its vertices embedded on the
/// unit sphere (graph Laplacian eigenvectors, then spherical Laplacian smoothing).
QuadSurface stuck_surface();

/// Checks of generated data, each returning "" when fine, else a message naming element ids.
/// The surface is closed, every edge in two quads traversed oppositely, every vertex used, vertex
/// fans single, one component, V - E + F = 2.
std::string check_surface(const QuadSurface& surface);
/// g.surface passes check_surface; known_mesh's first surface.points.size() points are the
/// surface's points; every face is used by one or two hexes (oppositely oriented); the faces used
/// once are exactly the surface's quads (same ids, same orientation); every vertex link is a
/// sphere (interior) or a disk (boundary); V - E + F - H = 1.
std::string check_known_mesh(const Generated& g);
/// Sorted chord lengths of a closed quad surface (a chord passing a quad twice counts it twice).
std::vector<int32_t> chord_lengths_of(const QuadSurface& surface);
/// True when all 8 corner Jacobians (kHexCornerFrames) of hex h are > 0.
bool hex_is_positive(const HexMesh& mesh, int32_t h);
/// Number of hexes with hex_is_positive.
int32_t count_positive_hexes(const HexMesh& mesh);

}  // namespace hexpeel::testing
