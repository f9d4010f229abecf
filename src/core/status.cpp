// Status codes, their names and the process exit codes derived from them.
#include "hexpeel/status.h"

#include <cstdio>
#include <stdexcept>

namespace hexpeel {

std::string_view to_string(StatusCode code) {
  switch (code) {
    case StatusCode::ok: return "ok";
    case StatusCode::io_error: return "io_error";
    case StatusCode::unsupported_format: return "unsupported_format";
    case StatusCode::parse_error: return "parse_error";
    case StatusCode::empty_mesh: return "empty_mesh";
    case StatusCode::index_out_of_range: return "index_out_of_range";
    case StatusCode::non_finite_coordinate: return "non_finite_coordinate";
    case StatusCode::non_quad_face: return "non_quad_face";
    case StatusCode::degenerate_quad: return "degenerate_quad";
    case StatusCode::duplicate_vertex: return "duplicate_vertex";
    case StatusCode::open_boundary: return "open_boundary";
    case StatusCode::non_manifold_edge: return "non_manifold_edge";
    case StatusCode::non_manifold_vertex: return "non_manifold_vertex";
    case StatusCode::inconsistent_orientation: return "inconsistent_orientation";
    case StatusCode::self_intersecting_surface: return "self_intersecting_surface";
    case StatusCode::multiple_components: return "multiple_components";
    case StatusCode::nonzero_genus: return "nonzero_genus";
    case StatusCode::odd_quad_count: return "odd_quad_count";
    case StatusCode::self_intersecting_chord: return "self_intersecting_chord";
    case StatusCode::stuck: return "stuck";
    case StatusCode::invalid_intrusion: return "invalid_intrusion";
    case StatusCode::invalid_mesh: return "invalid_mesh";
    case StatusCode::internal_error: return "internal_error";
  }
  return "unknown";
}

std::string to_string(const Status& status) {
  if (status.ok()) return "ok";
  return std::string(to_string(status.code)) + ": " + status.message;
}

int exit_code(const Status& status) {
  switch (status.code) {
    case StatusCode::ok: return 0;
    case StatusCode::stuck:
    case StatusCode::invalid_intrusion: return 3;
    case StatusCode::internal_error: return 4;
    default: return 2;
  }
}

void assertion_failed(const char* expr, const char* file, int line, const std::string& msg) {
  std::string text = std::string("hexpeel internal error: assertion `") + expr + "` failed at " +
                     file + ":" + std::to_string(line);
  if (!msg.empty()) text += " (" + msg + ")";
  throw std::logic_error(text);
}

}  // namespace hexpeel
