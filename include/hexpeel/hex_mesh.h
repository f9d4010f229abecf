// HexMesh: flat hex storage and THE local numbering table of the project.
//
// Corner order is VTK_HEXAHEDRON (= Gmsh type 5 = MEDIT Hexahedra = Exodus HEX8 = Abaqus C3D8):
//
//            7 -------- 6
//           /|         /|         0-1-2-3: bottom face; its right-hand normal (p1-p0)x(p3-p0)
//          / |        / |                  points towards the top face 4-5-6-7.
//         4 -------- 5  |         corner i+4 is joined to corner i.
//         |  3 ------|- 2         Unit cube: 0=(0,0,0) 1=(1,0,0) 2=(1,1,0) 3=(0,1,0)
//         | /        | /                     4=(0,0,1) 5=(1,0,1) 6=(1,1,1) 7=(0,1,1)
//         |/         |/           A positive hex has right-handed corner frames.
//         0 -------- 1
//
// Every reader and writer converts to and from this order; tests check each one against it.
#pragma once

#include "hexpeel/quad_surface.h"

#include <array>
#include <cstdint>
#include <vector>

namespace hexpeel {

using Hex = std::array<int32_t, 8>;

/// Local faces, corners ordered so the right-hand normal points OUT of the hex.
inline constexpr std::array<std::array<int, 4>, 6> kHexFaces{{
    {0, 3, 2, 1},  // bottom (-z on the unit cube)
    {4, 5, 6, 7},  // top    (+z)
    {0, 1, 5, 4},  // front  (-y)
    {1, 2, 6, 5},  // right  (+x)
    {2, 3, 7, 6},  // back   (+y)
    {3, 0, 4, 7},  // left   (-x)
}};

/// Local edges: 0-3 bottom ring, 4-7 top ring, 8-11 verticals.
inline constexpr std::array<std::array<int, 2>, 12> kHexEdges{{
    {0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7},
}};

/// For corner c: its three neighbours ordered so that (n0-c, n1-c, n2-c) is right-handed in a
/// positive hex (the corner frames Verdict's scaled Jacobian uses).
inline constexpr std::array<std::array<int, 3>, 8> kHexCornerFrames{{
    {1, 3, 4}, {2, 0, 5}, {3, 1, 6}, {0, 2, 7}, {7, 5, 0}, {4, 6, 1}, {5, 7, 2}, {6, 4, 3},
}};

struct HexMesh {
  std::vector<Vec3> points;
  std::vector<Hex> hexes;

  int32_t num_points() const { return static_cast<int32_t>(points.size()); }
  int32_t num_hexes() const { return static_cast<int32_t>(hexes.size()); }
};

/// The hex's corners reordered as its mirror image (0,3,2,1,4,7,6,5): flips the sign of every
/// corner Jacobian.
Hex mirrored(const Hex& h);

}  // namespace hexpeel
