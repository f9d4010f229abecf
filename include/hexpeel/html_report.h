// A self-contained HTML quality report of a hex mesh: the figures, a histogram of the scaled
// Jacobian, the worst hexes, and an interactive 3D view (WebGL, hand-written, no network) of the
// mesh cut by a plane, hexes coloured by scaled Jacobian, the worst ones highlighted.
#pragma once

#include "hexpeel/hex_mesh.h"
#include "hexpeel/quality.h"

#include <cstdint>
#include <string>

namespace hexpeel {

struct HtmlReportParams {
  std::string title = "hex mesh";  ///< shown as the page's heading (HTML-escaped)
  /// The 3D view embeds every point and hex; a mesh with more hexes than this gets the figures
  /// only, and the page says why.
  int32_t max_view_hexes = 400000;
};

/// The page for `mesh` and its quality report `q` (run_quality of the same mesh). Deterministic:
/// the same mesh and report give the same bytes.
std::string html_report(const HexMesh& mesh, const QualityReport& q, const HtmlReportParams& params = {});

}  // namespace hexpeel
