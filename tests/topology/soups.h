// Tiny hand-made polygon soups for the topology tests: voxel boundaries, a quad torus, and the
// "radial" quad mesh of a polyhedron (one quad per polyhedron edge), which gives closed genus-0
// quad surfaces with an odd number of quads and self-intersecting chords.
#pragma once

#include "hexpeel/hex_mesh.h"
#include "hexpeel/quad_surface.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <tuple>
#include <vector>

namespace hexpeel::test {

/// Boundary of a union of unit voxels (cells given by their min corner), outward oriented,
/// vertices numbered in order of first use.
inline PolygonSoup voxel_soup(const std::vector<std::array<int, 3>>& cells) {
  static constexpr int kCorner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                        {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  static constexpr int kNormal[6][3] = {{0, 0, -1}, {0, 0, 1}, {0, -1, 0},
                                        {1, 0, 0},  {0, 1, 0}, {-1, 0, 0}};
  auto filled = [&](int x, int y, int z) {
    for (const auto& c : cells)
      if (c[0] == x && c[1] == y && c[2] == z) return true;
    return false;
  };
  PolygonSoup soup;
  std::map<std::tuple<int, int, int>, int32_t> ids;
  for (const auto& c : cells)
    for (int f = 0; f < 6; ++f) {
      if (filled(c[0] + kNormal[f][0], c[1] + kNormal[f][1], c[2] + kNormal[f][2])) continue;
      std::array<int32_t, 4> quad;
      for (int i = 0; i < 4; ++i) {
        const int* k = kCorner[kHexFaces[f][i]];
        auto key = std::make_tuple(c[0] + k[0], c[1] + k[1], c[2] + k[2]);
        auto [it, inserted] = ids.emplace(key, static_cast<int32_t>(soup.points.size()));
        if (inserted) soup.points.emplace_back(std::get<0>(key), std::get<1>(key), std::get<2>(key));
        quad[i] = it->second;
      }
      soup.add_face({quad[0], quad[1], quad[2], quad[3]});
    }
  return soup;
}

/// The unit cube (8 vertices, 6 outward quads).
inline PolygonSoup cube_soup() { return voxel_soup({{0, 0, 0}}); }

/// n x n grid boundary: the surface of an n x n x n block of voxels.
inline PolygonSoup grid_soup(int n) {
  std::vector<std::array<int, 3>> cells;
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) cells.push_back({x, y, z});
  return voxel_soup(cells);
}

/// Torus with n x m quads (radii 2 and 0.75), outward oriented.
inline PolygonSoup torus_soup(int n, int m) {
  PolygonSoup soup;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      const double u = 2 * std::numbers::pi * i / n, v = 2 * std::numbers::pi * j / m;
      soup.points.emplace_back((2 + 0.75 * std::cos(v)) * std::cos(u),
                               (2 + 0.75 * std::cos(v)) * std::sin(u), 0.75 * std::sin(v));
    }
  auto id = [&](int i, int j) { return static_cast<int32_t>((i % n) * m + (j % m)); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) soup.add_face({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  return soup;
}

/// Quad Klein bottle: the n x m torus grid with its last column glued to the first reflected
/// (j -> m - j), so no orientation of its quads is consistent. Points on a torus (the glued
/// quads are long and skew, but not degenerate).
inline PolygonSoup klein_soup(int n, int m) {
  PolygonSoup soup = torus_soup(n, m);
  soup.indices.clear();
  soup.offsets.assign(1, 0);
  auto id = [&](int i, int j) {
    if (i == n) return static_cast<int32_t>((m - j % m) % m);
    return static_cast<int32_t>(i * m + (j % m));
  };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) soup.add_face({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  return soup;
}

/// Radial quad mesh of a polyhedron (faces counter-clockwise seen from outside): its vertices,
/// then one vertex per face (the face centroid pushed out by `lift` along the face normal), and
/// one quad (u, centre of the face right of u->w, w, centre of the face left of u->w) per edge.
/// Quads = polyhedron edges; its chords follow the polyhedron's Petrie polygons.
inline PolygonSoup radial_soup(const std::vector<Vec3>& points,
                               const std::vector<std::vector<int32_t>>& faces, double lift = 0.1) {
  PolygonSoup soup;
  soup.points = points;
  const int32_t nv = static_cast<int32_t>(points.size());
  std::map<std::pair<int32_t, int32_t>, int32_t> face_left;  // directed edge -> its face
  for (size_t f = 0; f < faces.size(); ++f) {
    Vec3 c = Vec3::Zero(), n = Vec3::Zero();
    const auto& fv = faces[f];
    for (size_t i = 0; i < fv.size(); ++i) {
      c += points[fv[i]];
      n += points[fv[i]].cross(points[fv[(i + 1) % fv.size()]]);
      face_left[{fv[i], fv[(i + 1) % fv.size()]}] = nv + static_cast<int32_t>(f);
    }
    soup.points.push_back(c / static_cast<double>(fv.size()) + lift * n.normalized());
  }
  for (const auto& [edge, left] : face_left)
    if (edge.first < edge.second)
      soup.add_face({edge.first, face_left.at({edge.second, edge.first}), edge.second, left});
  return soup;
}

/// Radial mesh of a triangular prism: 9 quads, 11 vertices, closed, genus 0.
inline PolygonSoup prism_radial_soup() {
  std::vector<Vec3> p;
  for (int z = 0; z < 2; ++z)
    for (int i = 0; i < 3; ++i) {
      const double a = 2 * std::numbers::pi * i / 3;
      p.emplace_back(std::cos(a), std::sin(a), z);
    }
  return radial_soup(p, {{0, 2, 1}, {3, 4, 5}, {0, 1, 4, 3}, {1, 2, 5, 4}, {2, 0, 3, 5}});
}

/// Returns the soup with face `f` reversed.
inline PolygonSoup with_face_reversed(PolygonSoup soup, int32_t f) {
  std::reverse(soup.indices.begin() + soup.offsets[f], soup.indices.begin() + soup.offsets[f + 1]);
  return soup;
}

/// Converts a soup known to be all quads into a QuadSurface.
inline QuadSurface to_surface(const PolygonSoup& soup) {
  QuadSurface s;
  s.points = soup.points;
  for (int32_t f = 0; f < soup.num_faces(); ++f)
    s.quads.push_back({soup.indices[soup.offsets[f]], soup.indices[soup.offsets[f] + 1],
                       soup.indices[soup.offsets[f] + 2], soup.indices[soup.offsets[f] + 3]});
  return s;
}

}  // namespace hexpeel::test
