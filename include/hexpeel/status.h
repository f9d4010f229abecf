// Status: the result of anything that can fail because of its input.
//
// Bad input is never an exception or a crash: every stage returns a Status whose code names the
// class of problem and whose message names the offending elements (ids, line numbers, byte
// offsets). A broken internal invariant is a bug and goes through HEXPEEL_ASSERT instead.
#pragma once

#include <string>
#include <string_view>

namespace hexpeel {

enum class StatusCode {
  ok = 0,
  // files
  io_error,             ///< cannot open, read, write or rename a file
  unsupported_format,   ///< unknown file extension or unsupported variant of a format
  parse_error,          ///< malformed or truncated file content
  empty_mesh,           ///< the file holds no faces / no hexes
  // surface checks (DESIGN.md "Input checking")
  index_out_of_range,   ///< a face refers to a vertex that does not exist
  non_finite_coordinate,///< NaN or infinite coordinate
  non_quad_face,        ///< a face with other than 4 corners
  degenerate_quad,      ///< repeated corner or zero area
  duplicate_vertex,     ///< two distinct vertices at the same position
  open_boundary,        ///< an edge used by one face only
  non_manifold_edge,    ///< an edge used by more than two faces
  non_manifold_vertex,  ///< the faces around a vertex form more than one fan
  inconsistent_orientation, ///< neighbouring faces traverse their shared edge the same way
  multiple_components,  ///< the surface falls into several edge-connected parts
  nonzero_genus,        ///< the surface is not a topological sphere
  odd_quad_count,       ///< no hex mesh has a boundary with an odd number of quads
  self_intersecting_chord, ///< a chord passes through a quad twice (method cannot handle it)
  self_intersecting_surface, ///< two quads cut through or touch each other (bounds no solid)
  // meshing
  stuck,                ///< no feasible elimination left before the cube
  invalid_intrusion,    ///< a concave step's intrusion would not remove |side| hexes
  invalid_mesh,         ///< a hex mesh given to us is not usable (bad ids, non-hex cells)
  internal_error,       ///< an invariant broke: a bug in hexpeel
};

/// Short stable identifier of a code, e.g. "open_boundary" (used in JSON and messages).
std::string_view to_string(StatusCode code);

struct Status {
  StatusCode code = StatusCode::ok;
  std::string message;  ///< human-readable, names elements; empty when ok

  bool ok() const { return code == StatusCode::ok; }
  static Status success() { return {}; }
  static Status error(StatusCode c, std::string msg) { return {c, std::move(msg)}; }
};

/// "open_boundary: edge (3,7) is used by quad 12 only" style one-liner.
std::string to_string(const Status& status);

/// Process exit code for a status: 0 ok, 2 input/file problems, 3 meshing failures, 4 bugs.
int exit_code(const Status& status);

[[noreturn]] void assertion_failed(const char* expr, const char* file, int line, const std::string& msg);

}  // namespace hexpeel

/// Internal invariant check, on in release builds too (STYLE.md "Errors").
#define HEXPEEL_ASSERT(expr)                                                   \
  do {                                                                         \
    if (!(expr)) ::hexpeel::assertion_failed(#expr, __FILE__, __LINE__, {});   \
  } while (false)
#define HEXPEEL_ASSERT_MSG(expr, msg)                                          \
  do {                                                                         \
    if (!(expr)) ::hexpeel::assertion_failed(#expr, __FILE__, __LINE__, (msg)); \
  } while (false)
