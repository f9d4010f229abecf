// Abaqus / CalculiX input deck (.inp) of a hex mesh: nodes, C3D8 elements, the boundary as a node
// set and as an element-based surface.
//
// C3D8 node order is VTK_HEXAHEDRON's (hex_mesh.h), so corners are written as stored, 1-based.
// Data lines hold at most 16 values (Abaqus' limit for set lines) and stay far below 256 chars.
#include "io/formats.h"
#include "io/hex_sides.h"

#include <string>
#include <vector>

namespace hexpeel::io {

namespace {

/// Abaqus C3D8 faces S1..S6 as VTK-order corners: 1-2-3-4, 5-8-7-6, 1-5-6-2, 2-6-7-3, 3-7-8-4,
/// 4-8-5-1 in the manual's 1-based node numbers.
constexpr SideTable kC3D8Faces{{
    {0, 1, 2, 3},
    {4, 7, 6, 5},
    {0, 4, 5, 1},
    {1, 5, 6, 2},
    {2, 6, 7, 3},
    {3, 7, 4, 0},
}};

constexpr size_t kValuesPerLine = 16;

/// Appends 0-based `ids` 1-based, comma separated, at most kValuesPerLine per line.
void append_id_lines(std::string& s, const std::vector<int32_t>& ids) {
  for (size_t i = 0; i < ids.size(); ++i) {
    append_int(s, int64_t{ids[i]} + 1);
    s += (i + 1 == ids.size() || (i + 1) % kValuesPerLine == 0) ? "\n" : ", ";
  }
}

void append_nodes(std::string& s, const HexMesh& mesh) {
  s += "*NODE\n";
  for (int32_t v = 0; v < mesh.num_points(); ++v) {
    const Vec3& p = mesh.points[v];
    append_int(s, int64_t{v} + 1);
    for (int k = 0; k < 3; ++k) {
      s += ", ";
      append_real(s, p[k]);
    }
    s += '\n';
  }
}

void append_elements(std::string& s, const HexMesh& mesh) {
  s += "*ELEMENT, TYPE=C3D8, ELSET=HEXES\n";
  for (int32_t h = 0; h < mesh.num_hexes(); ++h) {
    append_int(s, int64_t{h} + 1);
    for (int32_t v : mesh.hexes[h]) {
      s += ", ";
      append_int(s, int64_t{v} + 1);
    }
    s += '\n';
  }
}

/// One element set _<NAME>_Sk per face number k that occurs, then the surface NAME naming them.
void append_surface(std::string& s, const std::vector<HexSide>& sides, const std::string& name) {
  std::array<std::vector<int32_t>, 6> by_face;
  for (const HexSide& side : sides) by_face[side.side].push_back(side.hex);
  for (size_t k = 0; k < 6; ++k) {
    if (by_face[k].empty()) continue;
    s += "*ELSET, ELSET=_" + name + "_S" + std::to_string(k + 1) + "\n";
    append_id_lines(s, by_face[k]);
  }
  s += "*SURFACE, NAME=" + name + ", TYPE=ELEMENT\n";
  for (size_t k = 0; k < 6; ++k) {
    if (by_face[k].empty()) continue;
    s += "_" + name + "_S" + std::to_string(k + 1) + ", S" + std::to_string(k + 1) + "\n";
  }
}

}  // namespace

std::string write_abaqus(const HexMesh& mesh, const PatchLookup* patches) {
  std::string s = "*HEADING\nhexpeel hex mesh: ";
  append_int(s, mesh.num_points());
  s += " nodes, ";
  append_int(s, mesh.num_hexes());
  s += " C3D8 elements\n";
  append_nodes(s, mesh);
  append_elements(s, mesh);
  const std::vector<HexSide> sides = boundary_sides(mesh, kC3D8Faces);
  if (!sides.empty()) {
    s += "*NSET, NSET=BOUNDARY\n";
    append_id_lines(s, side_vertices(mesh, kC3D8Faces, sides));
    append_surface(s, sides, "BOUNDARY");
    if (patches != nullptr) {
      const std::vector<std::vector<HexSide>> parts = patches->by_patch(mesh, kC3D8Faces, sides);
      for (size_t k = 0; k < parts.size(); ++k)
        if (!parts[k].empty()) append_surface(s, parts[k], "PATCH_" + std::to_string(k + 1));
    }
  }
  return s;
}

}  // namespace hexpeel::io
