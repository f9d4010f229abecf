// Validation: turns the polygons a reader produced into a QuadSurface the mesher can use, or says
// precisely why it cannot (DESIGN.md "Input checking").
#pragma once

#include "hexpeel/context.h"
#include "hexpeel/quad_surface.h"
#include "hexpeel/status.h"

#include <string>
#include <vector>

namespace hexpeel {

struct ValidationParams {
  /// Two vertices closer than this (relative to the bbox diagonal) are duplicates. 0 = exact.
  double duplicate_tolerance = 0.0;
  /// A quad whose area is below this (relative to the squared bbox diagonal) is degenerate.
  double degenerate_area = 1e-14;
  /// Flip an inward-oriented surface (and warn) instead of rejecting it.
  bool flip_inward = true;
  /// Reverse the quads whose orientation disagrees with their neighbours' (as CAD exports write
  /// one face at a time) and warn, instead of rejecting the surface. A non-orientable surface is
  /// always rejected.
  bool reorient = true;
  /// Refuse a surface whose quads cut through or touch each other (intersection.h).
  bool check_self_intersection = true;
  /// Accept an odd number of quads (for surface repair, which makes the count even).
  bool allow_odd = false;
};

/// One problem found. Several may be found; the first error decides the status.
struct ValidationIssue {
  StatusCode code = StatusCode::ok;
  std::string message;          ///< names the element ids
  std::vector<int32_t> faces;   ///< offending face ids (input numbering), possibly truncated
  std::vector<int32_t> vertices;///< offending vertex ids (input numbering), possibly truncated
};

struct ValidationStats {
  int32_t points = 0, faces = 0, edges = 0;
  int32_t unused_vertices = 0;   ///< removed from the surface (warned)
  int32_t components = 0;
  int32_t genus = -1;            ///< -1 when not computed (surface not closed/manifold)
  bool flipped = false;          ///< input was inward and has been flipped
  /// quads reversed to agree with their neighbours before the inward check (input ids, sorted)
  std::vector<int32_t> reoriented;
};

struct ValidationResult {
  Status status;                        ///< ok, or the first issue's code and message
  std::vector<ValidationIssue> issues;  ///< every problem class found (one entry per class)
  std::vector<std::string> warnings;    ///< e.g. flipped orientation, unused vertices dropped
  QuadSurface surface;                  ///< valid only when status.ok(); outward oriented
  /// surface vertex -> input vertex (identity unless unused vertices were dropped)
  std::vector<int32_t> input_vertex;
  ValidationStats stats;
};

ValidationResult run_validation(const PolygonSoup& soup, const ValidationParams& params = {},
                                const Context& ctx = {});

}  // namespace hexpeel
