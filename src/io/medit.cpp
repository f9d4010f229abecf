// MEDIT / Gamma .mesh (ASCII): reads vertices and cells, writes a hex mesh.
//
// Keywords are read free-form (any whitespace, # comments). Kept: Vertices (Dimension 2 or 3),
// Triangles and Quadrilaterals (as surface polygons), Hexahedra (also spelled Hexaedra); counted
// as other cells: Edges, Tetrahedra, Prisms, Pyramids. Any other section (Corners, Ridges,
// Normals, Identifier...) is skipped by consuming the numbers that follow its keyword. Every
// entry ends with a reference number, which is ignored. Indices are 1-based. The binary .meshb
// variant is not read. The Hexahedra corner order is the VTK one (bottom 1234, top 5678 above
// it), so no permutation is applied.
#include "io/formats.h"

namespace hexpeel::io {

namespace {

struct MeditCells {
  std::string_view keyword;
  int corners;
  CellKind kind;
};

constexpr MeditCells kCellSections[] = {
    {"Edges", 2, CellKind::other},          {"Triangles", 3, CellKind::polygon},
    {"Quadrilaterals", 4, CellKind::polygon}, {"Tetrahedra", 4, CellKind::other},
    {"Pyramids", 5, CellKind::other},       {"Prisms", 6, CellKind::other},
    {"Hexahedra", 8, CellKind::hex},        {"Hexaedra", 8, CellKind::hex},
};

bool is_number(std::string_view t) {
  double d;
  return parse_real(t, d);
}

}  // namespace

Status read_medit(std::string_view data, const std::string& name, CellSoup& out) {
  TextCursor cur(data, name, '#');
  out.index_base = 1;
  int64_t dim = 3;
  bool has_version = false;
  std::string_view kw;
  int64_t corners[8];
  while (cur.next(kw)) {
    if (kw == "End") break;
    if (kw == "MeshVersionFormatted") {
      int64_t version = 0;
      if (Status s = cur.get_int(version, "the mesh version"); !s.ok()) return s;
      has_version = true;
      continue;
    }
    if (!has_version) {
      return cur.error("expected 'MeshVersionFormatted' first, found " + quoted(kw));
    }
    if (kw == "Dimension") {
      if (Status s = cur.get_int(dim, "the dimension"); !s.ok()) return s;
      if (dim != 2 && dim != 3) return cur.error("dimension must be 2 or 3, not " + std::to_string(dim));
      continue;
    }
    if (kw == "Vertices") {
      int64_t n = 0;
      if (Status s = cur.get_count(n, "vertex count", static_cast<int64_t>(cur.remaining()) / (dim + 1));
          !s.ok()) {
        return s;
      }
      out.points.reserve(out.points.size() + static_cast<size_t>(n));
      for (int64_t i = 0; i < n; ++i) {
        double xyz[3] = {0.0, 0.0, 0.0};
        for (int64_t k = 0; k < dim; ++k) {
          if (Status s = cur.get_real(xyz[k], "a vertex coordinate"); !s.ok()) return s;
        }
        int64_t ref;
        if (Status s = cur.get_int(ref, "the vertex reference"); !s.ok()) return s;
        out.points.emplace_back(xyz[0], xyz[1], xyz[2]);
      }
      continue;
    }
    const MeditCells* section = nullptr;
    for (const MeditCells& c : kCellSections) {
      if (kw == c.keyword) section = &c;
    }
    if (section != nullptr) {
      int64_t n = 0;
      const std::string what = std::string(section->keyword) + " count";
      if (Status s = cur.get_count(n, what, static_cast<int64_t>(cur.remaining()) / (section->corners + 1));
          !s.ok()) {
        return s;
      }
      for (int64_t i = 0; i < n; ++i) {
        const int64_t line = cur.next_line();
        for (int k = 0; k < section->corners; ++k) {
          if (Status s = cur.get_int(corners[k], "a vertex index"); !s.ok()) return s;
          corners[k] = corners[k] > 0 ? corners[k] - 1 : -1;  // 1-based; <= 0 is invalid
        }
        int64_t ref;
        if (Status s = cur.get_int(ref, "the element reference"); !s.ok()) return s;
        if (section->kind == CellKind::other) {
          out.add_other(at_line(line));
        } else {
          out.add_cell(section->kind, corners, static_cast<size_t>(section->corners), at_line(line));
        }
      }
      continue;
    }
    if (is_number(kw)) return cur.error("expected a keyword, found " + quoted(kw));
    // A section we do not use: its content is numbers up to the next keyword.
    std::string_view t;
    while (cur.peek(t) && is_number(t)) cur.next(t);
  }
  if (!has_version) return cur.error("not a MEDIT file: no 'MeshVersionFormatted' keyword");
  return Status::success();
}

std::string write_medit(const HexMesh& mesh, const PatchLookup* patches) {
  std::string s = "MeshVersionFormatted 2\nDimension 3\n\nVertices\n";
  append_int(s, mesh.num_points());
  s += '\n';
  for (const Vec3& p : mesh.points) {
    append_point(s, p);
    s += " 0\n";
  }
  s += "\nHexahedra\n";
  append_int(s, mesh.num_hexes());
  s += '\n';
  for (const Hex& h : mesh.hexes) {
    for (int32_t v : h) {
      append_int(s, int64_t{v} + 1);
      s += ' ';
    }
    s += "0\n";
  }
  if (patches != nullptr) {
    const BoundaryPatches& bp = *patches->patches;
    s += "\nQuadrilaterals\n";
    append_int(s, static_cast<int64_t>(bp.faces.size()));
    s += '\n';
    for (size_t i = 0; i < bp.faces.size(); ++i) {
      for (int32_t v : bp.faces[i]) {
        append_int(s, int64_t{v} + 1);
        s += ' ';
      }
      append_int(s, int64_t{bp.patch[i]} + 1);
      s += '\n';
    }
  }
  s += "\nEnd\n";
  return s;
}

}  // namespace hexpeel::io
