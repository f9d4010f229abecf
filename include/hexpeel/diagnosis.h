// Diagnosis of an input surface for `hexpeel check`: validation, chords and edge sharpness in one
// result, with the verdict whether dual cycle elimination can be tried on it at all.
#pragma once

#include "hexpeel/chords.h"
#include "hexpeel/context.h"
#include "hexpeel/status.h"
#include "hexpeel/validation.h"

#include <nlohmann/json.hpp>

#include <string>

namespace hexpeel {

struct SurfaceDiagnosis {
  ValidationResult validation;  ///< always filled
  /// Filled whenever the surface is closed, edge-manifold and consistently oriented (even if,
  /// say, its genus is wrong); empty otherwise.
  ChordSet chords;
  ChordStats chord_stats;
  /// Filled when the surface is valid (convex and concave need the outward orientation).
  EdgeGeometry edges;
  double sharp_angle_deg = 60.0;  ///< the threshold `edges` was classified with
  /// ok only when the surface is valid and every chord is simple; otherwise the validation
  /// status, or self_intersecting_chord.
  Status status;
};

/// The way `mesh` would take with this surface, in one line: dual cycle elimination, or why
/// none applies (for `hexpeel check`).
std::string mesh_path(const SurfaceDiagnosis& diagnosis);

/// Validates `soup`, finds its chords and classifies its edges (sharp above `sharp_angle_deg`,
/// degrees of deviation from flat, range (0, 180)).
SurfaceDiagnosis diagnose_surface(const PolygonSoup& soup, double sharp_angle_deg = 60.0,
                                  const Context& ctx = {},
                                  const ValidationParams& validation = {});

/// Human-readable report: status, counts, genus, components, chords, sharp edges.
std::string to_text(const SurfaceDiagnosis& diagnosis);
/// The same as JSON (stable keys; status codes by their `to_string` names).
nlohmann::json to_json(const SurfaceDiagnosis& diagnosis);

}  // namespace hexpeel
