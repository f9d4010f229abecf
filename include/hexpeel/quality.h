// Quality of a hex mesh: Verdict's hex scaled Jacobian, singular edges, Euler characteristic,
// ball test, and (optionally) whether the mesh's boundary equals a given surface.
#pragma once

#include "hexpeel/context.h"
#include "hexpeel/hex_mesh.h"
#include "hexpeel/quad_surface.h"

#include <nlohmann/json.hpp>

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace hexpeel {

/// Verdict's hex scaled Jacobian (verdict v_hex_scaled_jacobian): the minimum over the 8 corner
/// Jacobians and the centre (principal axes) Jacobian, each divided by its three column lengths.
/// A zero-length edge or axis (squared length <= VERDICT_DBL_MIN = 1e-30, absolute, as in
/// VTK's Verdict) makes the hex degenerate: the value is then `kDegenerateScaledJacobian`
/// (Verdict returns VERDICT_DBL_MAX; we count those as <= 0). Otherwise the value is in [-1, 1].
inline constexpr double kDegenerateScaledJacobian = -2.0;
double scaled_jacobian(const std::array<Vec3, 8>& corners);
/// One of the nine terms whose minimum scaled_jacobian is: term 0 is the centre (principal
/// axes), term 1 + c corner c (kHexCornerFrames[c]); kDegenerateScaledJacobian when one of its
/// columns has zero length. So scaled_jacobian is exactly the minimum of the nine terms.
double scaled_jacobian_term(const std::array<Vec3, 8>& corners, int term);

struct QualityParams {
  int histogram_bins = 20;   ///< bins over [-1, 1] (1..1000)
  int worst_count = 10;      ///< how many worst hexes to list (0..1000)
  double boundary_tolerance = 1e-6;  ///< relative to the surface's bbox diagonal, for --surface
};

struct WorstHex {
  int32_t hex = -1;
  double scaled_jacobian = 0.0;
  Vec3 centroid = Vec3::Zero();
};

struct QualityReport {
  int32_t hexes = 0;
  int32_t points = 0;
  // scaled Jacobian. min/mean/max are over the non-degenerate hexes; NaN when there are none
  // (empty mesh, or every hex degenerate), written as null in JSON and "n/a" in text.
  // A hex with a corner id outside the point array is treated as degenerate.
  double sj_min = 0.0, sj_mean = 0.0, sj_max = 0.0;
  int32_t sj_count_nonpositive = 0;  ///< SJ <= 0, degenerate hexes included
  int32_t sj_degenerate = 0;         ///< zero-length edge or axis
  std::vector<int32_t> histogram;    ///< histogram_bins counts over [-1, 1]; degenerate in bin 0
  std::vector<WorstHex> worst;       ///< worst first (degenerate = -2 first), ties by id
  std::vector<double> per_hex_sj;    ///< one value per hex
  // topology
  int32_t singular_edges_interior = 0;  ///< interior edges with valence != 4
  int32_t singular_edges_boundary = 0;  ///< boundary edges with other than 2 hexes
  int32_t vertices = 0, edges = 0, faces = 0;  ///< of the complex (used points only)
  int32_t boundary_faces = 0;
  int64_t euler_characteristic = 0;     ///< V - E + F - C
  bool faces_manifold = true;           ///< every face used by one or two hexes
  /// chi = 1, every face used by 1 or 2 hexes, every edge link a cycle (interior) or a path
  /// (boundary), every vertex link a 2-sphere (interior) or a disk (boundary), hexes connected
  /// through faces, boundary one component with chi = 2. False for an empty mesh.
  bool is_ball = false;
  std::string topology_message;         ///< every failed check with a count and the first ids
  // boundary vs surface (when a surface was given)
  std::optional<bool> boundary_matches_surface;
  std::string boundary_message;         ///< first difference found, when not matching
};

/// Computes the full report. `surface` (optional) is compared with the mesh boundary: positions
/// within tolerance, same set of quads up to rotation and reversal.
QualityReport run_quality(const HexMesh& mesh, const QualityParams& params = {},
                          const QuadSurface* surface = nullptr, const Context& ctx = {});

/// The report as JSON: hexes, points, scaled_jacobian{min,mean,max,count_nonpositive,degenerate,
/// histogram{lo,hi,counts},worst[{id,sj,centroid}]}, singular_edges{interior,boundary},
/// complex{vertices,edges,faces,boundary_faces,faces_manifold}, euler_characteristic, is_ball,
/// topology_message, boundary_matches_surface (only when a surface was given), boundary_message
/// (always; empty when no surface was given or it matched). min/mean/max are null when no hex
/// is non-degenerate; a degenerate hex in "worst" has sj = kDegenerateScaledJacobian (-2).
nlohmann::json to_json(const QualityReport& report);

/// Multi-line human-readable text of the report.
std::string to_text(const QualityReport& report);

}  // namespace hexpeel
