// Wavefront OBJ: reads `v` and `f` lines of a polygon surface, writes a quad surface.
//
// Reading: face corners may be written `i`, `i/t`, `i//n` or `i/t/n`; negative indices count
// back from the last vertex defined so far. Comments (#) and every other statement of the OBJ
// format (vt, vn, g, o, s, usemtl, mtllib, l...) are ignored; a line that starts with anything
// else is an error naming it (random bytes or another format given the .obj extension). A vertex may carry a fourth (w) or colour values: only
// x y z are kept. Indices are 1-based in the file; they are range-checked by io.cpp.
#include "io/formats.h"

namespace hexpeel::io {

namespace {

/// The statements of the OBJ format (Wavefront's specification) other than v and f.
bool is_obj_keyword(std::string_view t) {
  static constexpr std::string_view kKeywords[] = {
      "vt", "vn", "vp", "l", "p", "g", "o", "s", "mg", "usemtl", "mtllib", "usemap", "maplib",
      "cstype", "deg", "bmat", "step", "curv", "curv2", "surf", "parm", "trim", "hole", "scrv",
      "sp", "end", "con", "bevel", "c_interp", "d_interp", "lod", "shadow_obj", "trace_obj",
      "ctech", "stech", "call", "csh", "res", "bsp", "bzp", "cdc", "cdp"};
  for (std::string_view k : kKeywords)
    if (t == k) return true;
  return false;
}

}  // namespace

Status read_obj(std::string_view data, const std::string& name, CellSoup& out) {
  TextCursor cur(data, name, '#');
  out.index_base = 1;
  std::vector<int64_t> face;
  std::string_view tok;
  while (cur.next(tok)) {
    const int64_t line = cur.line();
    if (tok == "v") {
      double xyz[3];
      for (double& c : xyz) {
        std::string_view t;
        if (!cur.next_in_line(t)) return cur.error("vertex has fewer than 3 coordinates");
        if (!parse_real(t, c)) return cur.error("expected a vertex coordinate, found " + quoted(t));
      }
      out.points.emplace_back(xyz[0], xyz[1], xyz[2]);
    } else if (tok == "f") {
      face.clear();
      std::string_view t;
      while (cur.next_in_line(t)) {
        const std::string_view first = t.substr(0, t.find('/'));
        int64_t i = 0;
        if (!parse_int(first, i) || i == 0) {
          return cur.error("expected a vertex index (a non-zero integer), found " + quoted(t));
        }
        // 1-based absolute, or relative to the vertices read so far; 0-based here.
        const auto read_so_far = static_cast<int64_t>(out.points.size());
        if (i < -read_so_far) {  // (not -i: i may be INT64_MIN)
          return Status::error(StatusCode::index_out_of_range,
                               located(name, at_line(line),
                                       "relative vertex index " + std::to_string(i) +
                                           " points before the first vertex (" +
                                           std::to_string(read_so_far) + " read so far)"));
        }
        face.push_back(i > 0 ? i - 1 : read_so_far + i);
      }
      if (face.empty()) return cur.error("face has no vertices");
      out.add_cell(CellKind::polygon, face.data(), face.size(), at_line(line));
    } else if (!is_obj_keyword(tok)) {
      return cur.error("expected an OBJ statement ('v', 'f', 'vn', 'g', ...) or a comment, found " +
                       quoted(tok) + "; is this an OBJ file?");
    }
    cur.skip_line();
  }
  return Status::success();
}

std::string write_obj(const QuadSurface& surface) {
  std::string s = "# quad surface written by hexpeel\n";
  for (const Vec3& p : surface.points) {
    s += "v ";
    append_point(s, p);
    s += '\n';
  }
  for (const Quad& q : surface.quads) {
    s += 'f';
    for (int32_t v : q) {
      s += ' ';
      append_int(s, int64_t{v} + 1);
    }
    s += '\n';
  }
  return s;
}

}  // namespace hexpeel::io
