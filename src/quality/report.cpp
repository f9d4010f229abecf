// The quality report of a hex mesh (DESIGN.md "Quality"): per-hex scaled Jacobian with its
// statistics, histogram and worst hexes; the topology of the complex (topology.cpp); and,
// when a surface is given, whether the mesh boundary equals it (boundary_match.cpp).
//
// The per-hex scaled Jacobians are computed in parallel over fixed blocks of hexes; each block
// writes its own slice of per_hex_sj and its own partial sums, and the partials are combined in
// block order afterwards, so every figure is identical for any number of threads.
// Input: any HexMesh (bad point ids make those hexes degenerate and fail the topology).
#include "hexpeel/quality.h"

#include "quality_internal.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cmath>
#include <iomanip>
#include <limits>
#include <numeric>
#include <sstream>

namespace hexpeel {
namespace {

constexpr size_t kBlock = 2048;  // hexes per parallel work item; fixed so reductions are too

// Statistics of one block of hexes; degenerate hexes are not part of sum/min/max.
struct BlockStats {
  double sum = 0.0;
  double min = std::numeric_limits<double>::infinity();
  double max = -std::numeric_limits<double>::infinity();
  int32_t valid = 0;        // non-degenerate hexes
  int32_t nonpositive = 0;  // degenerate included
  int32_t degenerate = 0;
};

bool ids_valid(const Hex& h, int32_t np) {
  return std::all_of(h.begin(), h.end(), [np](int32_t v) { return v >= 0 && v < np; });
}

std::array<Vec3, 8> corners_of(const HexMesh& mesh, const Hex& h) {
  std::array<Vec3, 8> c;
  for (int k = 0; k < 8; ++k) c[k] = mesh.points[h[k]];
  return c;
}

nlohmann::json number_or_null(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
}

}  // namespace

QualityReport run_quality(const HexMesh& mesh, const QualityParams& params,
                          const QuadSurface* surface, const Context& ctx) {
  // Far from unit size: measured on a copy scaled by a power of two (quality is scale-free),
  // the centroids scaled back.
  if (const int k = scale_exponent(mesh.points); k != 0) {
    HexMesh scaled = mesh;
    scale_points(scaled.points, k);
    QuadSurface scaled_surface;
    if (surface) {
      scaled_surface = *surface;
      scale_points(scaled_surface.points, k);
    }
    QualityReport r = run_quality(scaled, params, surface ? &scaled_surface : nullptr, ctx);
    for (WorstHex& w : r.worst) w.centroid = std::ldexp(1.0, -k) * w.centroid;
    return r;
  }
  QualityReport r;
  const int32_t nh = mesh.num_hexes(), np = mesh.num_points();
  r.hexes = nh;
  r.points = np;
  const int bins = std::clamp(params.histogram_bins, 1, 1000);
  const int worst_count = std::clamp(params.worst_count, 0, 1000);
  if (bins != params.histogram_bins || worst_count != params.worst_count)
    ctx.warn("quality: histogram_bins or worst_count out of range, clamped");
  ctx.report("quality", 0.0);

  // Scaled Jacobian per hex, in parallel over fixed blocks.
  r.per_hex_sj.assign(nh, kDegenerateScaledJacobian);
  const size_t n_blocks = (static_cast<size_t>(nh) + kBlock - 1) / kBlock;
  std::vector<BlockStats> blocks(n_blocks);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n_blocks, 1), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t b = range.begin(); b != range.end(); ++b) {
      BlockStats& s = blocks[b];
      const size_t end = std::min(static_cast<size_t>(nh), (b + 1) * kBlock);
      for (size_t h = b * kBlock; h < end; ++h) {
        const Hex& hex = mesh.hexes[h];
        const double sj = ids_valid(hex, np) ? scaled_jacobian(corners_of(mesh, hex))
                                             : kDegenerateScaledJacobian;
        r.per_hex_sj[h] = sj;
        if (sj == kDegenerateScaledJacobian) {
          ++s.degenerate;
          ++s.nonpositive;
          continue;
        }
        ++s.valid;
        s.sum += sj;
        s.min = std::min(s.min, sj);
        s.max = std::max(s.max, sj);
        if (sj <= 0.0) ++s.nonpositive;
      }
    }
  });
  BlockStats all;
  for (const BlockStats& s : blocks) {
    all.sum += s.sum;
    all.min = std::min(all.min, s.min);
    all.max = std::max(all.max, s.max);
    all.valid += s.valid;
    all.nonpositive += s.nonpositive;
    all.degenerate += s.degenerate;
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  r.sj_min = all.valid > 0 ? all.min : nan;
  r.sj_max = all.valid > 0 ? all.max : nan;
  r.sj_mean = all.valid > 0 ? all.sum / all.valid : nan;
  r.sj_count_nonpositive = all.nonpositive;
  r.sj_degenerate = all.degenerate;

  r.histogram.assign(bins, 0);
  for (double sj : r.per_hex_sj) {
    const double t = std::floor((sj + 1.0) * 0.5 * bins);
    r.histogram[static_cast<size_t>(std::clamp(t, 0.0, static_cast<double>(bins - 1)))]++;
  }

  // Worst hexes: lowest scaled Jacobian first (degenerate ones lowest of all), ties by id.
  std::vector<int32_t> order(nh);
  std::iota(order.begin(), order.end(), 0);
  const auto n_worst = std::min<size_t>(worst_count, order.size());
  std::partial_sort(order.begin(), order.begin() + n_worst, order.end(), [&](int32_t a, int32_t b) {
    return std::tie(r.per_hex_sj[a], a) < std::tie(r.per_hex_sj[b], b);
  });
  for (size_t i = 0; i < n_worst; ++i) {
    const int32_t h = order[i];
    WorstHex w;
    w.hex = h;
    w.scaled_jacobian = r.per_hex_sj[h];
    if (ids_valid(mesh.hexes[h], np)) {
      for (const Vec3& p : corners_of(mesh, mesh.hexes[h])) w.centroid += p;
      w.centroid /= 8.0;
    }
    r.worst.push_back(w);
  }
  ctx.report("quality", 0.4);

  const quality_detail::ComplexTopology topo = quality_detail::analyze_topology(mesh);
  r.singular_edges_interior = topo.singular_edges_interior;
  r.singular_edges_boundary = topo.singular_edges_boundary;
  r.vertices = topo.vertices;
  r.edges = topo.edges;
  r.faces = topo.faces;
  r.boundary_faces = topo.boundary_faces;
  r.euler_characteristic = topo.euler_characteristic;
  r.faces_manifold = topo.faces_manifold;
  r.is_ball = topo.is_ball;
  r.topology_message = topo.message;
  ctx.report("quality", 0.8);

  if (surface) {
    const quality_detail::BoundaryMatch m =
        quality_detail::match_boundary(mesh, topo, *surface, params.boundary_tolerance);
    r.boundary_matches_surface = m.matches;
    r.boundary_message = m.message;
  }
  ctx.report("quality", 1.0);
  return r;
}

nlohmann::json to_json(const QualityReport& r) {
  nlohmann::json worst = nlohmann::json::array();
  for (const WorstHex& w : r.worst)
    worst.push_back({{"id", w.hex},
                     {"sj", w.scaled_jacobian},
                     {"centroid", {number_or_null(w.centroid.x()), number_or_null(w.centroid.y()),
                                   number_or_null(w.centroid.z())}}});
  nlohmann::json j;
  j["hexes"] = r.hexes;
  j["points"] = r.points;
  j["scaled_jacobian"] = {{"min", number_or_null(r.sj_min)},
                          {"mean", number_or_null(r.sj_mean)},
                          {"max", number_or_null(r.sj_max)},
                          {"count_nonpositive", r.sj_count_nonpositive},
                          {"degenerate", r.sj_degenerate},
                          {"histogram", {{"lo", -1.0}, {"hi", 1.0}, {"counts", r.histogram}}},
                          {"worst", worst}};
  j["singular_edges"] = {{"interior", r.singular_edges_interior},
                         {"boundary", r.singular_edges_boundary}};
  j["complex"] = {{"vertices", r.vertices},
                  {"edges", r.edges},
                  {"faces", r.faces},
                  {"boundary_faces", r.boundary_faces},
                  {"faces_manifold", r.faces_manifold}};
  j["euler_characteristic"] = r.euler_characteristic;
  j["is_ball"] = r.is_ball;
  j["topology_message"] = r.topology_message;
  if (r.boundary_matches_surface) j["boundary_matches_surface"] = *r.boundary_matches_surface;
  j["boundary_message"] = r.boundary_message;
  return j;
}

std::string to_text(const QualityReport& r) {
  std::ostringstream s;
  auto num = [](double x) {
    std::ostringstream t;
    if (std::isfinite(x))
      t << std::fixed << std::setprecision(6) << x;
    else
      t << "n/a";
    return t.str();
  };
  s << "hexes: " << r.hexes << "  points: " << r.points << '\n';
  s << "scaled Jacobian: min " << num(r.sj_min) << "  mean " << num(r.sj_mean) << "  max "
    << num(r.sj_max) << '\n';
  s << "hexes with SJ <= 0: " << r.sj_count_nonpositive << " (degenerate: " << r.sj_degenerate
    << ")\n";
  s << "histogram over [-1, 1] in " << r.histogram.size() << " bins:";
  for (int32_t c : r.histogram) s << ' ' << c;
  s << '\n';
  if (!r.worst.empty()) {
    s << "worst hexes:\n";
    for (const WorstHex& w : r.worst)
      s << "  hex " << w.hex << "  SJ "
        << (w.scaled_jacobian == kDegenerateScaledJacobian ? std::string("degenerate")
                                                           : num(w.scaled_jacobian))
        << "  centroid (" << w.centroid.x() << ", " << w.centroid.y() << ", " << w.centroid.z()
        << ")\n";
  }
  s << "singular edges: interior " << r.singular_edges_interior << ", boundary "
    << r.singular_edges_boundary << '\n';
  s << "complex: V " << r.vertices << "  E " << r.edges << "  F " << r.faces << "  C " << r.hexes
    << "  boundary faces " << r.boundary_faces << "  Euler characteristic "
    << r.euler_characteristic << '\n';
  s << "topological ball: " << (r.is_ball ? "yes" : "no");
  if (!r.topology_message.empty()) s << " (" << r.topology_message << ')';
  s << '\n';
  if (r.boundary_matches_surface) {
    s << "boundary equals surface: " << (*r.boundary_matches_surface ? "yes" : "no");
    if (!r.boundary_message.empty()) s << " (" << r.boundary_message << ')';
    s << '\n';
  }
  return s.str();
}

}  // namespace hexpeel
