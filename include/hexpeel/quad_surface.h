// Surfaces: the raw polygons a reader produces, and the checked all-quad surface the mesher uses.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>  // Vec3::cross

#include <array>
#include <cstdint>
#include <vector>

namespace hexpeel {

using Vec3 = Eigen::Vector3d;
using Quad = std::array<int32_t, 4>;

/// What a surface reader produces: points and polygons of any size, not yet checked.
/// Polygon f has corners `indices[offsets[f] .. offsets[f+1])`, 0-based. Readers guarantee that
/// offsets is well formed (offsets.front() == 0, non-decreasing, offsets.back() == indices.size())
/// and report indices that are out of range themselves; everything else is validation's job.
struct PolygonSoup {
  std::vector<Vec3> points;
  std::vector<int32_t> offsets{0};
  std::vector<int32_t> indices;

  int32_t num_faces() const { return static_cast<int32_t>(offsets.size()) - 1; }
  int32_t face_size(int32_t f) const { return offsets[f + 1] - offsets[f]; }
  void add_face(std::initializer_list<int32_t> corners) {
    indices.insert(indices.end(), corners.begin(), corners.end());
    offsets.push_back(static_cast<int32_t>(indices.size()));
  }
};

/// A closed all-quad surface. After validation: genus 0, manifold, one component, outward
/// orientation (corners counter-clockwise seen from outside), every vertex used.
/// Half-edge k of quad q runs from corner k to corner (k+1)%4 and has id 4*q+k.
struct QuadSurface {
  std::vector<Vec3> points;
  std::vector<Quad> quads;

  int32_t num_points() const { return static_cast<int32_t>(points.size()); }
  int32_t num_quads() const { return static_cast<int32_t>(quads.size()); }
};

/// The surface as polygons (what a reader would give), e.g. to run the pipeline on a generated
/// surface.
PolygonSoup to_polygon_soup(const QuadSurface& surface);

/// Half-edge adjacency of a closed quad surface, built in one pass.
/// opposite[4*q+k] is the half-edge of the neighbouring quad across edge k of q, or -1 when the
/// edge is a boundary or non-manifold edge (validation rejects those).
struct QuadAdjacency {
  std::vector<int32_t> opposite;
};

/// Builds the adjacency; edges used by other than two half-edges get -1 on all their half-edges.
QuadAdjacency build_adjacency(const QuadSurface& surface);

/// Outward unit normal of a quad (from its diagonals) and its centroid.
Vec3 quad_normal(const QuadSurface& surface, int32_t q);
Vec3 quad_centroid(const QuadSurface& surface, int32_t q);

/// Signed volume enclosed by a closed surface (positive when outward oriented).
double signed_volume(const QuadSurface& surface);

/// Scale normalization: the k for which 2^k brings the largest extent of the points' bounding
/// box into [1, 2), when that extent lies outside [2^-16, 2^16] (areas, determinants and
/// tolerances then work on numbers of moderate size, whatever the units); 0 otherwise, and for
/// no points or non-finite coordinates (which validation reports).
int scale_exponent(const std::vector<Vec3>& points);
/// Multiplies every coordinate by 2^k: exact, and undone exactly by -k, unless a result over-
/// or underflows.
void scale_points(std::vector<Vec3>& points, int k);

}  // namespace hexpeel
