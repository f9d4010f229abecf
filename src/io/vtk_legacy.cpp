// Legacy VTK (.vtk): reads POLYDATA polygons and UNSTRUCTURED_GRID cells, ASCII or BINARY
// (big-endian); writes a hex mesh as an ASCII UNSTRUCTURED_GRID.
//
// Both cell layouts are read: the classic one ("CELLS n size", each cell as count + indices) and
// the one of file version 5 ("CELLS nOffsets nConnectivity" followed by OFFSETS and CONNECTIVITY
// arrays). Cell types: 12 hexahedron, 11 voxel (reordered), 9 quad, 7 polygon, 5 triangle; other
// types are counted as other cells. POLYDATA VERTICES/LINES/TRIANGLE_STRIPS are counted as other
// cells. METADATA blocks are skipped; reading stops at the first POINT_DATA, CELL_DATA or FIELD
// section, since nothing we need comes after it. Counts are checked against the bytes left.
#include "io/formats.h"

#include <optional>

namespace hexpeel::io {

namespace {

std::optional<Scalar> vtk_type(std::string_view t) {
  if (t == "unsigned_char") return Scalar::u8;
  if (t == "char") return Scalar::i8;
  if (t == "unsigned_short") return Scalar::u16;
  if (t == "short") return Scalar::i16;
  if (t == "unsigned_int" || t == "vtktypeuint32") return Scalar::u32;
  if (t == "int" || t == "vtktypeint32") return Scalar::i32;
  if (t == "unsigned_long" || t == "vtktypeuint64") return Scalar::u64;
  if (t == "long" || t == "vtktypeint64") return Scalar::i64;
  if (t == "float") return Scalar::f32;
  if (t == "double") return Scalar::f64;
  return std::nullopt;
}

/// Cells as read from CELLS (or a POLYDATA section), before their types are known.
struct VtkCells {
  std::vector<int64_t> offsets{0};
  std::vector<int64_t> conn;
  std::vector<Where> where;
};

class VtkReader {
 public:
  VtkReader(TextCursor& cur, bool binary) : cur_(cur), binary_(binary) {}

  Where where() {
    return binary_ ? at_byte(static_cast<int64_t>(cur_.pos())) : at_line(cur_.next_line());
  }
  Status error(const std::string& msg) { return parse_error(cur_.name(), where(), msg); }

  /// Prepares for `n` values of `type` after a keyword line; checks they fit in the file.
  Status begin_values(int64_t n, Scalar type, std::string_view what) {
    if (binary_) cur_.skip_line();
    const int64_t each = binary_ ? static_cast<int64_t>(scalar_size(type)) : 2;
    if (n < 0 || n > static_cast<int64_t>(cur_.remaining()) / each) {
      return error(std::string(what) + " " + std::to_string(n) +
                   " is negative or more than the rest of the file can hold");
    }
    return Status::success();
  }
  Status real(Scalar type, double& v, std::string_view what) {
    if (!binary_) return cur_.get_real(v, what);
    ByteCursor bc(cur_.data(), cur_.pos(), true);
    if (!bc.get_real(type, v)) return error("expected " + std::string(what) + ", found end of file");
    cur_.jump_to(bc.pos());
    return Status::success();
  }
  Status integer(Scalar type, int64_t& v, std::string_view what) {
    if (!binary_) return cur_.get_int(v, what);
    ByteCursor bc(cur_.data(), cur_.pos(), true);
    if (!bc.get_int(type, v)) return error("expected " + std::string(what) + ", found end of file");
    cur_.jump_to(bc.pos());
    return Status::success();
  }

  /// Reads `keyword type` then n integers (the version-5 OFFSETS / CONNECTIVITY arrays).
  Status typed_array(std::string_view keyword, int64_t n, std::vector<int64_t>& out) {
    std::string_view tok, type_name;
    if (!cur_.next(tok) || tok != keyword) return error("expected '" + std::string(keyword) + "'");
    if (!cur_.next_in_line(type_name)) return error("expected the data type of " + std::string(keyword));
    const auto type = vtk_type(type_name);
    if (!type) return error("unknown data type " + quoted(type_name));
    if (Status s = begin_values(n, *type, std::string(keyword) + " size"); !s.ok()) return s;
    out.resize(static_cast<size_t>(n));
    for (int64_t& v : out) {
      if (Status s = integer(*type, v, std::string(keyword) + " entry"); !s.ok()) return s;
    }
    return Status::success();
  }

  /// Reads a cell array after "KEYWORD a b" (either layout).
  Status cells(int64_t a, int64_t b, VtkCells& out) {
    std::string_view next;
    const bool v5 = cur_.peek(next) && next == "OFFSETS";
    if (v5) {
      const Where w = where();
      if (Status s = typed_array("OFFSETS", a, out.offsets); !s.ok()) return s;
      if (Status s = typed_array("CONNECTIVITY", b, out.conn); !s.ok()) return s;
      if (out.offsets.empty() || out.offsets.front() != 0 || out.offsets.back() != b) {
        return parse_error(cur_.name(), w, "OFFSETS must start at 0 and end at the CONNECTIVITY size");
      }
      for (size_t i = 1; i < out.offsets.size(); ++i) {
        if (out.offsets[i] < out.offsets[i - 1]) {
          return parse_error(cur_.name(), w, "OFFSETS decrease at entry " + std::to_string(i));
        }
      }
      out.where.assign(out.offsets.size() - 1, w);
      return Status::success();
    }
    if (Status s = begin_values(b, Scalar::i32, "cell list size"); !s.ok()) return s;
    if (a < 0 || a > b) return error("cell count " + std::to_string(a) + " does not fit the list size");
    out.conn.reserve(static_cast<size_t>(b - a));
    for (int64_t c = 0; c < a; ++c) {
      const Where w = where();
      int64_t n = 0;
      if (Status s = integer(Scalar::i32, n, "a cell size"); !s.ok()) return s;
      if (n < 0 || n > b - static_cast<int64_t>(out.conn.size()) - c - 1) {
        return parse_error(cur_.name(), w, "cell " + std::to_string(c) + " has impossible size " + std::to_string(n));
      }
      for (int64_t k = 0; k < n; ++k) {
        int64_t v = 0;
        if (Status s = integer(Scalar::i32, v, "a cell corner"); !s.ok()) return s;
        out.conn.push_back(v);
      }
      out.offsets.push_back(static_cast<int64_t>(out.conn.size()));
      out.where.push_back(w);
    }
    if (static_cast<int64_t>(out.conn.size()) + a != b) {
      return error("cell list size is " + std::to_string(b) + " but the cells hold " +
                   std::to_string(out.conn.size() + a) + " numbers");
    }
    return Status::success();
  }

 private:
  TextCursor& cur_;
  bool binary_;
};

}  // namespace

Status read_vtk_legacy(std::string_view data, const std::string& name, CellSoup& out) {
  TextCursor cur(data, name);
  if (cur.rest_of_line().substr(0, 14) != "# vtk DataFile") {
    return cur.error_at(1, "not a legacy VTK file: expected '# vtk DataFile Version ...'");
  }
  cur.rest_of_line();  // title
  std::string_view tok;
  if (!cur.next(tok)) return cur.error("expected ASCII or BINARY, found end of file");
  const bool binary = tok == "BINARY";
  if (!binary && tok != "ASCII") return cur.error("expected ASCII or BINARY, found " + quoted(tok));
  std::string_view dataset;
  if (!cur.next(tok) || tok != "DATASET" || !cur.next(dataset)) return cur.error("expected 'DATASET <type>'");
  const bool polydata = dataset == "POLYDATA";
  if (!polydata && dataset != "UNSTRUCTURED_GRID") {
    return Status::error(StatusCode::unsupported_format,
                         located(name, at_line(cur.line()),
                                 "dataset " + quoted(dataset) + " is not supported (POLYDATA and UNSTRUCTURED_GRID are)"));
  }
  VtkReader rd(cur, binary);
  bool have_points = false;
  VtkCells pending;  // UNSTRUCTURED_GRID cells waiting for CELL_TYPES
  bool have_cells = false;
  while (cur.next(tok)) {
    const int64_t line = cur.line();
    if (tok == "POINTS") {
      std::string_view count, type_name;
      int64_t n = 0;
      if (!cur.next_in_line(count) || !parse_int(count, n) || !cur.next_in_line(type_name)) {
        return cur.error("expected 'POINTS <count> <type>'");
      }
      const auto type = vtk_type(type_name);
      if (!type) return cur.error("unknown data type " + quoted(type_name));
      if (Status s = rd.begin_values(n, *type, "point count"); !s.ok()) return s;
      if (n > static_cast<int64_t>(cur.remaining()) / 3) return rd.error("point count too large");
      out.points.reserve(static_cast<size_t>(n));
      for (int64_t i = 0; i < n; ++i) {
        double xyz[3];
        for (double& c : xyz) {
          if (Status s = rd.real(*type, c, "a point coordinate"); !s.ok()) return s;
        }
        out.points.emplace_back(xyz[0], xyz[1], xyz[2]);
      }
      have_points = true;
    } else if (tok == "CELLS" || (polydata && (tok == "POLYGONS" || tok == "VERTICES" ||
                                               tok == "LINES" || tok == "TRIANGLE_STRIPS"))) {
      std::string_view ta, tb;
      int64_t a = 0, b = 0;
      if (!cur.next_in_line(ta) || !cur.next_in_line(tb) || !parse_int(ta, a) || !parse_int(tb, b)) {
        return cur.error("expected '" + std::string(tok) + " <count> <size>'");
      }
      const bool cells = tok == "CELLS";
      const bool polygons = tok == "POLYGONS";
      VtkCells vc;
      if (Status s = rd.cells(a, b, vc); !s.ok()) return s;
      if (cells) {
        pending = std::move(vc);
        have_cells = true;
        continue;
      }
      for (size_t c = 0; c + 1 < vc.offsets.size(); ++c) {
        if (polygons) {
          out.add_cell(CellKind::polygon, vc.conn.data() + vc.offsets[c],
                       static_cast<size_t>(vc.offsets[c + 1] - vc.offsets[c]), vc.where[c]);
        } else {
          out.add_other(vc.where[c]);
        }
      }
    } else if (tok == "CELL_TYPES") {
      std::string_view count;
      int64_t n = 0;
      if (!cur.next_in_line(count) || !parse_int(count, n)) return cur.error("expected 'CELL_TYPES <count>'");
      if (!have_cells) return cur.error("CELL_TYPES before CELLS");
      const int64_t ncells = static_cast<int64_t>(pending.offsets.size()) - 1;
      if (n != ncells) {
        return cur.error("CELL_TYPES count " + std::to_string(n) + " differs from the " +
                         std::to_string(ncells) + " cells");
      }
      if (Status s = rd.begin_values(n, Scalar::i32, "cell type count"); !s.ok()) return s;
      for (int64_t c = 0; c < n; ++c) {
        int64_t type = 0;
        if (Status s = rd.integer(Scalar::i32, type, "a cell type"); !s.ok()) return s;
        const int64_t begin = pending.offsets[c];
        const size_t size = static_cast<size_t>(pending.offsets[c + 1] - begin);
        if (!add_vtk_cell(out, type, pending.conn.data() + begin, size, pending.where[c])) {
          return parse_error(name, pending.where[c],
                             "cell " + std::to_string(c) + " of type " + std::to_string(type) +
                                 " has " + std::to_string(size) + " corners");
        }
      }
      have_cells = false;
    } else if (tok == "METADATA") {
      cur.skip_line();  // the block runs to the next empty line
      bool blank = false;
      while (!blank && cur.remaining() > 0) blank = cur.rest_of_line().empty();
    } else if (tok == "POINT_DATA" || tok == "CELL_DATA" || tok == "FIELD") {
      break;
    } else {
      return cur.error_at(line, "unexpected keyword " + quoted(tok));
    }
  }
  if (!have_points) return cur.error("no POINTS section");
  if (have_cells) return cur.error("CELLS without CELL_TYPES");
  return Status::success();
}

std::string write_vtk_legacy(const HexMesh& mesh, const PatchLookup* /*patches: none in VTK*/) {
  const int64_t np = mesh.num_points(), nh = mesh.num_hexes();
  std::string s = "# vtk DataFile Version 4.2\nhex mesh written by hexpeel\nASCII\n"
                  "DATASET UNSTRUCTURED_GRID\nPOINTS ";
  append_int(s, np);
  s += " double\n";
  for (const Vec3& p : mesh.points) {
    append_point(s, p);
    s += '\n';
  }
  s += "CELLS ";
  append_int(s, nh);
  s += ' ';
  append_int(s, 9 * nh);
  s += '\n';
  for (const Hex& h : mesh.hexes) {
    s += '8';
    for (int32_t v : h) (s += ' ', append_int(s, v));
    s += '\n';
  }
  s += "CELL_TYPES ";
  append_int(s, nh);
  s += '\n';
  for (int64_t h = 0; h < nh; ++h) s += "12\n";
  return s;
}

}  // namespace hexpeel::io
