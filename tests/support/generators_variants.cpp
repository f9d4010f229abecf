// Variants of a generated surface: tangential perturbation (perturbed, jittered) and uniform 2x2
// refinement of the surface with the matching 2x2x2 refinement of its known hex mesh.
//
// Both keep the vertex-id contract of Generated: surface vertices first in known_mesh, the known
// mesh's boundary equal to the surface. Perturbation keeps the combinatorics (chords unchanged);
// refinement doubles every chord into two chords of twice the length.
#include "support/generators_internal.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>

namespace hexpeel::testing {
namespace {

/// Per surface vertex: a random displacement in its tangent plane (normal = sum of the incident
/// quads' unit normals), uniform in the disk of radius amount x shortest incident edge.
std::vector<Vec3> tangent_displacements(const QuadSurface& s, uint64_t seed, double amount) {
  const int32_t np = s.num_points();
  std::vector<Vec3> normal(np, Vec3::Zero());
  std::vector<double> shortest(np, std::numeric_limits<double>::infinity());
  for (int32_t q = 0; q < s.num_quads(); ++q) {
    const Vec3 n = quad_normal(s, q);
    for (int k = 0; k < 4; ++k) {
      const int32_t v = s.quads[q][k], w = s.quads[q][(k + 1) & 3];
      normal[v] += n;
      const double len = (s.points[v] - s.points[w]).norm();
      shortest[v] = std::min(shortest[v], len);
      shortest[w] = std::min(shortest[w], len);
    }
  }
  detail::Rng rng(seed);
  std::vector<Vec3> d(np, Vec3::Zero());
  for (int32_t v = 0; v < np; ++v) {
    const double angle = 2.0 * std::numbers::pi * rng.uniform();
    const double radius = amount * shortest[v] * std::sqrt(rng.uniform());
    if (normal[v].norm() == 0.0 || !std::isfinite(shortest[v])) continue;
    const Vec3 n = normal[v].normalized();
    Eigen::Index axis = 0;
    n.cwiseAbs().minCoeff(&axis);
    const Vec3 t1 = n.cross(Vec3::Unit(axis)).normalized(), t2 = n.cross(t1);
    d[v] = radius * (std::cos(angle) * t1 + std::sin(angle) * t2);
  }
  return d;
}

/// Parametric corner (u,v,w) of the VTK hex corner c, and back.
constexpr int kCornerU[8] = {0, 1, 1, 0, 0, 1, 1, 0};
constexpr int kCornerV[8] = {0, 0, 1, 1, 0, 0, 1, 1};
int hex_corner(int u, int v, int w) { return (w ? 4 : 0) + (v ? (u ? 2 : 3) : (u ? 1 : 0)); }

/// Parameter values covered by lattice coordinate a of a 2x2(x2) split: 0 -> {0}, 2 -> {1},
/// 1 -> {0, 1} (the midpoint).
std::vector<int> params(int a) { return a == 1 ? std::vector<int>{0, 1} : std::vector<int>{a / 2}; }

/// Ids of the refined mesh: a lattice point is named by the sorted old vertex ids it averages
/// (1, 2 or 4 of them; hex centres are never shared and get fresh ids).
struct Refiner {
  const std::vector<Vec3>& old_points;    ///< positions of the old vertex ids
  std::vector<Vec3> points;               ///< the refined mesh's points, in id order
  std::map<Quad, int32_t> shared;         ///< sorted ids padded with -1 -> new id
  std::function<int32_t(int32_t)> keep;   ///< new id of an old vertex

  int32_t get(std::vector<int32_t> ids) {
    if (ids.size() == 1) return keep(ids[0]);
    Vec3 p = Vec3::Zero();
    for (int32_t v : ids) p += old_points[v];
    p /= static_cast<double>(ids.size());
    if (ids.size() == 8) {
      points.push_back(p);
      return static_cast<int32_t>(points.size()) - 1;
    }
    std::sort(ids.begin(), ids.end());
    Quad key{-1, -1, -1, -1};
    std::copy(ids.begin(), ids.end(), key.begin());
    auto [it, inserted] = shared.emplace(key, static_cast<int32_t>(points.size()));
    if (inserted) points.push_back(p);
    return it->second;
  }
};

}  // namespace

Generated perturbed(const Generated& g, uint64_t seed, double amount) {
  Generated out = g;
  out.name = g.name + "_perturbed_s" + std::to_string(seed);
  const std::vector<Vec3> d = tangent_displacements(g.surface, seed, amount);
  for (int32_t v = 0; v < g.surface.num_points(); ++v) {
    out.surface.points[v] += d[v];
    if (v < out.known_mesh.num_points()) out.known_mesh.points[v] = out.surface.points[v];
  }
  return out;
}

Generated jittered(const Generated& g, uint64_t seed, double amount) {
  Generated out = perturbed(g, seed, amount);
  out.name = g.name + "_jittered_s" + std::to_string(seed);
  HexMesh& mesh = out.known_mesh;
  const int32_t nb = g.surface.num_points(), np = mesh.num_points();
  if (np <= nb) return out;
  std::vector<double> shortest(np, std::numeric_limits<double>::infinity());
  for (const Hex& hex : g.known_mesh.hexes)
    for (const auto& e : kHexEdges) {
      const int32_t a = hex[e[0]], b = hex[e[1]];
      const double len = (g.known_mesh.points[a] - g.known_mesh.points[b]).norm();
      shortest[a] = std::min(shortest[a], len);
      shortest[b] = std::min(shortest[b], len);
    }
  detail::Rng rng(seed ^ 0x9e3779b97f4a7c15ULL);  // own stream: the surface stays as perturbed
  for (int32_t v = nb; v < np; ++v) {
    Vec3 x;
    do {
      x = Vec3(2 * rng.uniform() - 1, 2 * rng.uniform() - 1, 2 * rng.uniform() - 1);
    } while (x.squaredNorm() > 1.0);
    if (std::isfinite(shortest[v])) mesh.points[v] += amount * shortest[v] * x;
  }
  return out;
}

Generated refined(const Generated& g) {
  Generated out;
  out.name = g.name + "_refined";
  if (g.surface.quads.empty()) return out;
  const int32_t nb = g.surface.num_points();
  const bool has_mesh = !g.known_mesh.hexes.empty();
  Refiner r{has_mesh ? g.known_mesh.points : g.surface.points, g.surface.points, {},
            [](int32_t v) { return v; }};
  auto add_quads = [&](const Quad& q, std::vector<Quad>& quads) {
    int32_t lattice[3][3];
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        std::vector<int32_t> ids;
        for (int u : params(a))
          for (int v : params(b)) ids.push_back(q[v ? (u ? 2 : 3) : (u ? 1 : 0)]);
        lattice[a][b] = r.get(ids);
      }
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        quads.push_back(
            {lattice[i][j], lattice[i + 1][j], lattice[i + 1][j + 1], lattice[i][j + 1]});
  };
  for (const Quad& q : g.surface.quads) add_quads(q, out.surface.quads);
  const int32_t ns = static_cast<int32_t>(r.points.size());
  out.surface.points = r.points;

  if (has_mesh) {
    // Old interior vertices follow the new surface vertices; new interior ones come last.
    r.points.insert(r.points.end(), g.known_mesh.points.begin() + nb, g.known_mesh.points.end());
    r.keep = [nb, ns](int32_t v) { return v < nb ? v : ns + (v - nb); };
    for (const Hex& hex : g.known_mesh.hexes) {
      int32_t lattice[3][3][3];
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          for (int c = 0; c < 3; ++c) {
            std::vector<int32_t> ids;
            for (int u : params(a))
              for (int v : params(b))
                for (int w : params(c)) ids.push_back(hex[hex_corner(u, v, w)]);
            lattice[a][b][c] = r.get(ids);
          }
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j)
          for (int k = 0; k < 2; ++k) {
            Hex h;
            for (int c = 0; c < 8; ++c)
              h[c] = lattice[i + kCornerU[c]][j + kCornerV[c]][k + (c >= 4 ? 1 : 0)];
            out.known_mesh.hexes.push_back(h);
          }
    }
    out.known_mesh.points = r.points;
  }
  out.chord_lengths = chord_lengths_of(out.surface);
  out.chords = static_cast<int32_t>(out.chord_lengths.size());
  return out;
}

}  // namespace hexpeel::testing
