// Object File Format (OFF): reads a polygon surface, writes a quad surface.
//
// Accepts the OFF, COFF, NOFF, STOFF... variants (extra per-vertex and per-face values such as
// colours or normals are skipped: each vertex and face is read from its own line, the rest of
// the line is ignored). 4OFF/nOFF (other dimensions) and binary OFF are reported as unsupported.
// Comments (#) and blank lines are skipped. Indices are 0-based.
#include "io/formats.h"

namespace hexpeel::io {

Status read_off(std::string_view data, const std::string& name, CellSoup& out) {
  TextCursor cur(data, name, '#');
  std::string_view tok;
  if (!cur.next(tok)) return cur.error("expected the OFF header, found end of file");
  if (tok.size() < 3 || tok.substr(tok.size() - 3) != "OFF") {
    return cur.error("expected the OFF header, found " + quoted(tok));
  }
  if (tok.find('4') != std::string_view::npos || tok[0] == 'n') {
    return Status::error(StatusCode::unsupported_format,
                         name + ": " + std::string(tok) + " (non-3D OFF) is not supported");
  }
  if (std::string_view t; cur.peek(t) && t == "BINARY") {
    return Status::error(StatusCode::unsupported_format, name + ": binary OFF is not supported");
  }
  const int64_t room = static_cast<int64_t>(data.size());
  int64_t nv = 0, nf = 0;
  if (Status s = cur.get_count(nv, "vertex count", room); !s.ok()) return s;
  if (Status s = cur.get_count(nf, "face count", room); !s.ok()) return s;
  cur.skip_line();  // the edge count, unused
  if (nv > static_cast<int64_t>(cur.remaining()) / 2) {
    return cur.error("vertex count " + std::to_string(nv) + " is more than the file can hold");
  }
  out.points.reserve(static_cast<size_t>(nv));
  for (int64_t i = 0; i < nv; ++i) {
    double xyz[3];
    for (double& c : xyz) {
      if (Status s = cur.get_real(c, "a vertex coordinate"); !s.ok()) return s;
    }
    out.points.emplace_back(xyz[0], xyz[1], xyz[2]);
    cur.skip_line();
  }
  std::vector<int64_t> face;
  for (int64_t f = 0; f < nf; ++f) {
    int64_t n = 0;
    if (Status s = cur.get_count(n, "face corner count", static_cast<int64_t>(cur.remaining()));
        !s.ok()) {
      return s;
    }
    const int64_t line = cur.line();
    face.resize(static_cast<size_t>(n));
    for (int64_t& v : face) {
      if (Status s = cur.get_int(v, "a vertex index"); !s.ok()) return s;
    }
    out.add_cell(CellKind::polygon, face.data(), face.size(), at_line(line));
    cur.skip_line();
  }
  return Status::success();
}

std::string write_off(const QuadSurface& surface) {
  std::string s = "OFF\n";
  append_int(s, surface.num_points());
  s += ' ';
  append_int(s, surface.num_quads());
  s += " 0\n";
  for (const Vec3& p : surface.points) {
    append_point(s, p);
    s += '\n';
  }
  for (const Quad& q : surface.quads) {
    s += '4';
    for (int32_t v : q) {
      s += ' ';
      append_int(s, v);
    }
    s += '\n';
  }
  return s;
}

}  // namespace hexpeel::io
