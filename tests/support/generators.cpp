// Generators of genus-0 closed quad surfaces with a known hex mesh: grid cubes, cubed spheres and
// voxel solids (given, named or grown at random).
//
// Every generator builds the hex mesh first and takes its boundary as the surface
// (detail::from_hex_mesh), so "boundary of known_mesh == surface" holds by construction and the
// chords are walked on the result. Voxel solids are checked at the voxel level (face-connected,
// boundary a manifold sphere) before they are split; anything else yields an empty Generated.
#include "support/generators_internal.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace hexpeel::testing {
namespace detail {

HexMesh grid_mesh(int nx, int ny, int nz, const std::function<Vec3(int, int, int)>& position,
                  const std::vector<uint8_t>& filled) {
  HexMesh mesh;
  auto pid = [&](int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); };
  mesh.points.resize(static_cast<size_t>(nx + 1) * (ny + 1) * (nz + 1));
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) mesh.points[pid(i, j, k)] = position(i, j, k);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        if (!filled.empty() && !filled[i + nx * (j + ny * k)]) continue;
        mesh.hexes.push_back({pid(i, j, k), pid(i + 1, j, k), pid(i + 1, j + 1, k),
                              pid(i, j + 1, k), pid(i, j, k + 1), pid(i + 1, j, k + 1),
                              pid(i + 1, j + 1, k + 1), pid(i, j + 1, k + 1)});
      }
  return mesh;
}

}  // namespace detail

namespace {

using detail::from_hex_mesh;
using detail::grid_mesh;

/// True when the filled voxels are face-connected and their union's boundary is a manifold
/// sphere (which excludes edge/vertex-only contacts, cavities and tunnels).
bool voxels_form_ball(int nx, int ny, int nz, const std::vector<uint8_t>& filled) {
  const int n = nx * ny * nz;
  int first = -1, count = 0;
  for (int c = 0; c < n; ++c)
    if (filled[c]) {
      if (first < 0) first = c;
      ++count;
    }
  if (count == 0) return false;
  std::vector<uint8_t> seen(n, 0);
  std::vector<int> stack{first};
  seen[first] = 1;
  int reached = 0;
  while (!stack.empty()) {
    const int c = stack.back();
    stack.pop_back();
    ++reached;
    const int i = c % nx, j = (c / nx) % ny, k = c / (nx * ny);
    const int nbr[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k},
                           {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
    for (const auto& d : nbr) {
      if (d[0] < 0 || d[0] >= nx || d[1] < 0 || d[1] >= ny || d[2] < 0 || d[2] >= nz) continue;
      const int c2 = d[0] + nx * (d[1] + ny * d[2]);
      if (filled[c2] && !seen[c2]) {
        seen[c2] = 1;
        stack.push_back(c2);
      }
    }
  }
  if (reached != count) return false;
  const Generated g = from_hex_mesh(
      "", grid_mesh(nx, ny, nz, [](int i, int j, int k) { return Vec3(i, j, k); }, filled));
  return check_surface(g.surface).empty();
}

/// The cube [-1,1]^3 point p mapped onto the ball: the shell max|p_i| = r goes to the sphere of
/// radius r. Equiangular: on each shell, the face coordinates t are first warped by tan(pi/4 t).
Vec3 cube_to_ball(const Vec3& p, bool equiangular) {
  const double r = p.cwiseAbs().maxCoeff();
  if (r == 0.0) return Vec3::Zero();
  Vec3 q = p / r;
  if (equiangular)
    for (int i = 0; i < 3; ++i) q[i] = std::tan(std::numbers::pi / 4.0 * q[i]);
  return r * q.normalized();
}

Generated sphere(int n, bool equiangular) {
  n = std::max(n, 1);
  auto position = [n](int i, int j, int k) -> Vec3 {
    return Vec3(2 * i - n, 2 * j - n, 2 * k - n) / static_cast<double>(n);
  };
  HexMesh mesh = grid_mesh(n, n, n, position);
  for (Vec3& p : mesh.points) p = cube_to_ball(p, equiangular);
  return from_hex_mesh((equiangular ? "csphere_eq_n" : "csphere_n") + std::to_string(n), mesh);
}

/// A named voxel arrangement: grid size, filled cells and the canonical name.
struct Shape {
  int nx = 0, ny = 0, nz = 0;
  std::vector<uint8_t> filled;
  std::string name;
};

Shape make_shape(const std::string& shape) {
  Shape s;
  auto box = [&s](int nx, int ny, int nz, uint8_t value) {
    s.nx = nx;
    s.ny = ny;
    s.nz = nz;
    s.filled.assign(static_cast<size_t>(nx) * ny * nz, value);
  };
  auto set = [&s](int i, int j, int k, uint8_t value) {
    s.filled[i + s.nx * (j + s.ny * k)] = value;
  };
  if (shape == "L" || shape == "L3") {
    // Three voxels: (0,0) with its +x and +y neighbours, one layer thick.
    box(2, 2, 1, 1);
    set(1, 1, 0, 0);
    s.name = "L3";
  } else if (shape == "Lblock") {
    // An L of five columns (x=0 for y=0..2, and y=0 for x=1..2), two voxels high: 10 voxels.
    box(3, 3, 2, 0);
    for (int k = 0; k < 2; ++k) {
      for (int j = 0; j < 3; ++j) set(0, j, k, 1);
      for (int i = 1; i < 3; ++i) set(i, 0, k, 1);
    }
    s.name = "Lblock";
  } else if (shape == "U" || shape == "U3x3x1") {
    // 3x3x1 minus the centre and the middle of the y=2 row: 7 voxels, open towards +y.
    box(3, 3, 1, 1);
    set(1, 1, 0, 0);
    set(1, 2, 0, 0);
    s.name = "U3x3x1";
  } else if (shape == "T" || shape == "T4") {
    // A row of three along x at y=1 with one voxel below its middle: 4 voxels.
    box(3, 2, 1, 0);
    for (int i = 0; i < 3; ++i) set(i, 1, 0, 1);
    set(1, 0, 0, 1);
    s.name = "T4";
  } else if (shape == "pocket" || shape == "pocket3x3x2") {
    // 3x3x2 with a one-voxel dimple in the middle of the top: 17 voxels.
    box(3, 3, 2, 1);
    set(1, 1, 1, 0);
    s.name = "pocket3x3x2";
  } else if (shape == "notch" || shape == "notch3x3x3") {
    // 3x3x3 minus the row along y at the (x max, z max) edge: 24 voxels.
    box(3, 3, 3, 1);
    for (int j = 0; j < 3; ++j) set(2, j, 2, 0);
    s.name = "notch3x3x3";
  } else if (shape == "stairs" || shape == "stairs3") {
    // A 2D staircase one voxel deep: columns of heights 3, 2, 1 along x: 6 voxels.
    box(3, 1, 3, 0);
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3 - i; ++k) set(i, 0, k, 1);
    s.name = "stairs3";
  } else if (shape == "steps" || shape == "steps3") {
    // A corner staircase on a 3x3 footprint: height 3 - max(x, y), i.e. 3, 2, 1: 12 voxels.
    box(3, 3, 3, 0);
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3 - std::max(i, j); ++k) set(i, j, k, 1);
    s.name = "steps3";
  }
  return s;
}

}  // namespace

Generated cube(int nx, int ny, int nz, double size) {
  nx = std::max(nx, 1);
  ny = std::max(ny, 1);
  nz = std::max(nz, 1);
  auto position = [size](int i, int j, int k) -> Vec3 { return Vec3(i, j, k) * size; };
  return from_hex_mesh("cube_" + std::to_string(nx) + "x" + std::to_string(ny) + "x" +
                           std::to_string(nz),
                       grid_mesh(nx, ny, nz, position));
}

Generated cubed_sphere(int n) { return sphere(n, false); }

Generated cubed_sphere_equiangular(int n) { return sphere(n, true); }

Generated voxel_solid(int nx, int ny, int nz, const std::vector<uint8_t>& filled, int m,
                      const std::string& name) {
  Generated empty;
  empty.name = name + "_m" + std::to_string(m);
  if (nx < 1 || ny < 1 || nz < 1 || m < 1 ||
      filled.size() != static_cast<size_t>(nx) * ny * nz || !voxels_form_ball(nx, ny, nz, filled))
    return empty;
  std::vector<uint8_t> fine(static_cast<size_t>(nx) * ny * nz * m * m * m);
  const int fx = nx * m, fy = ny * m, fz = nz * m;
  for (int k = 0; k < fz; ++k)
    for (int j = 0; j < fy; ++j)
      for (int i = 0; i < fx; ++i)
        fine[i + fx * (j + fy * k)] = filled[i / m + nx * (j / m + ny * (k / m))];
  auto position = [m](int i, int j, int k) -> Vec3 {
    return Vec3(i, j, k) / static_cast<double>(m);
  };
  return from_hex_mesh(empty.name, grid_mesh(fx, fy, fz, position, fine));
}

Generated random_voxel_solid(uint64_t seed, int n, int cells, int m) {
  n = std::max(n, 1);
  const int total = n * n * n;
  cells = std::clamp(cells, 1, total);
  detail::Rng rng(seed);
  std::vector<uint8_t> filled(total, 0), rejected(total, 0);
  filled[n / 2 + n * (n / 2 + n * (n / 2))] = 1;
  int count = 1;
  std::vector<int> candidates;
  while (count < cells) {
    // Empty cells with a filled face neighbour, ascending: the order the rng indexes into.
    candidates.clear();
    for (int c = 0; c < total; ++c) {
      if (filled[c] || rejected[c]) continue;
      const int i = c % n, j = (c / n) % n, k = c / (n * n);
      const bool touches = (i > 0 && filled[c - 1]) || (i + 1 < n && filled[c + 1]) ||
                           (j > 0 && filled[c - n]) || (j + 1 < n && filled[c + n]) ||
                           (k > 0 && filled[c - n * n]) || (k + 1 < n && filled[c + n * n]);
      if (touches) candidates.push_back(c);
    }
    if (candidates.empty()) break;
    const int c = candidates[rng.below(candidates.size())];
    filled[c] = 1;
    if (voxels_form_ball(n, n, n, filled)) {
      ++count;
      std::fill(rejected.begin(), rejected.end(), 0);  // may have become addable
    } else {
      filled[c] = 0;
      rejected[c] = 1;
    }
  }
  return voxel_solid(n, n, n, filled, m,
                     "rvox_s" + std::to_string(seed) + "_n" + std::to_string(n) + "_c" +
                         std::to_string(cells));
}

Generated named_solid(const std::string& shape, int m) {
  const Shape s = make_shape(shape);
  if (s.filled.empty()) {
    Generated empty;
    empty.name = "vox_" + shape + "_m" + std::to_string(m);
    return empty;
  }
  return voxel_solid(s.nx, s.ny, s.nz, s.filled, m, "vox_" + s.name);
}

QuadSurface stuck_surface() {
  QuadSurface s;
  s.points = {
      {-0.873962, 0.045922, 0.483819},
      {-0.999975, 0.000979, -0.007019},
      {-0.898376, -0.437906, 0.034059},
      {-0.760277, -0.594770, 0.261206},
      {-0.001618, -0.995795, 0.091594},
      {0.755369, -0.596254, 0.271844},
      {0.867173, 0.044217, 0.496040},
      {-0.006899, 0.091603, 0.995772},
      {0.001618, 0.995795, -0.091594},
      {0.757367, 0.633401, 0.158739},
      {0.896950, -0.439664, 0.046660},
      {0.999975, -0.000979, 0.007019},
      {0.898376, 0.437906, -0.034059},
      {0.006899, -0.091603, -0.995772},
      {0.873962, -0.045922, -0.483819},
      {0.758278, -0.634886, -0.148101},
      {0.760277, 0.594770, -0.261206},
      {-0.757367, -0.633401, -0.158739},
      {-0.867173, -0.044217, -0.496040},
      {-0.758278, 0.634886, 0.148101},
      {-0.896950, 0.439664, -0.046660},
      {-0.755369, 0.596254, -0.271844}};
  s.quads = {{0, 1, 2, 3}, {4, 5, 6, 7}, {8, 7, 6, 9}, {6, 5, 10, 11}, {9, 6, 11, 12}, {4, 13, 14, 15}, {15, 10, 5, 4}, {16, 14, 13, 8}, {9, 12, 16, 8}, {12, 11, 14, 16}, {14, 11, 10, 15}, {4, 3, 2, 17}, {18, 13, 4, 17}, {0, 19, 20, 1}, {8, 13, 18, 21}, {19, 8, 21, 20}, {17, 2, 1, 18}, {21, 18, 1, 20}, {7, 0, 3, 4}, {19, 0, 7, 8}};
  return s;
}


}  // namespace hexpeel::testing
