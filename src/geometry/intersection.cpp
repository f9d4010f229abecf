// Self-intersection of a quad surface (intersection.h): quads as triangles, a uniform grid as the
// broad phase, segment-triangle tests as the exact phase.
//
// Two triangles meet iff an edge of one meets the other (in general position the ends of their
// common segment lie on edges; coplanar, an overlap contains an edge point of one inside the
// other), so six segment-triangle tests decide a pair. Triangles sharing one vertex v meet
// elsewhere iff the edge of one opposite v meets the other. Orientation signs use a tolerance
// relative to the lengths involved, so that touching counts as meeting and round-off on
// coplanar neighbours does not.
#include "hexpeel/intersection.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace hexpeel {
namespace {

constexpr double kRelTol = 1e-12;

int sign_of(double x, double tol) { return x > tol ? 1 : (x < -tol ? -1 : 0); }

/// Sign of the volume of (a, b, c, d): positive when d is on the side of the plane abc that its
/// right-hand normal points to.
int orient3(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Vec3 u = b - a, v = c - a, w = d - a;
  const double det = u.cross(v).dot(w);
  return sign_of(det, kRelTol * u.norm() * v.norm() * w.norm());
}

using Vec2 = Eigen::Vector2d;

int orient2(const Vec2& a, const Vec2& b, const Vec2& c) {
  const Vec2 u = b - a, v = c - a;
  const double det = u.x() * v.y() - u.y() * v.x();
  return sign_of(det, kRelTol * u.norm() * v.norm());
}

bool segments_meet_2d(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const int o1 = orient2(a, b, c), o2 = orient2(a, b, d), o3 = orient2(c, d, a), o4 = orient2(c, d, b);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  auto on_segment = [](const Vec2& p, const Vec2& q, const Vec2& r) {  // r on pq, given collinear
    return std::min(p.x(), q.x()) <= r.x() && r.x() <= std::max(p.x(), q.x()) &&
           std::min(p.y(), q.y()) <= r.y() && r.y() <= std::max(p.y(), q.y());
  };
  return (o1 == 0 && on_segment(a, b, c)) || (o2 == 0 && on_segment(a, b, d)) ||
         (o3 == 0 && on_segment(c, d, a)) || (o4 == 0 && on_segment(c, d, b));
}

bool point_in_triangle_2d(const Vec2& p, const std::array<Vec2, 3>& t) {
  const int a = orient2(t[0], t[1], p), b = orient2(t[1], t[2], p), c = orient2(t[2], t[0], p);
  return !((a < 0 || b < 0 || c < 0) && (a > 0 || b > 0 || c > 0));
}

/// Segment s0s1 against triangle t, all in t's plane: projected along t's largest normal axis.
bool segment_meets_triangle_coplanar(const Vec3& s0, const Vec3& s1, const std::array<Vec3, 3>& t) {
  const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
  int drop = 0;
  if (std::abs(n.y()) > std::abs(n[drop])) drop = 1;
  if (std::abs(n.z()) > std::abs(n[drop])) drop = 2;
  const int i = drop == 0 ? 1 : 0, j = drop == 2 ? 1 : 2;
  auto p2 = [&](const Vec3& p) { return Vec2(p[i], p[j]); };
  const std::array<Vec2, 3> t2{p2(t[0]), p2(t[1]), p2(t[2])};
  const Vec2 a = p2(s0), b = p2(s1);
  if (point_in_triangle_2d(a, t2) || point_in_triangle_2d(b, t2)) return true;
  for (int k = 0; k < 3; ++k)
    if (segments_meet_2d(a, b, t2[k], t2[(k + 1) % 3])) return true;
  return false;
}

bool segment_meets_triangle(const Vec3& s0, const Vec3& s1, const std::array<Vec3, 3>& t) {
  const int o0 = orient3(t[0], t[1], t[2], s0), o1 = orient3(t[0], t[1], t[2], s1);
  if (o0 * o1 > 0) return false;
  if (o0 == 0 && o1 == 0) return segment_meets_triangle_coplanar(s0, s1, t);
  const int a = orient3(s0, s1, t[0], t[1]), b = orient3(s0, s1, t[1], t[2]),
            c = orient3(s0, s1, t[2], t[0]);
  return !((a < 0 || b < 0 || c < 0) && (a > 0 || b > 0 || c > 0));
}

struct Triangle {
  std::array<int32_t, 3> v;
  int32_t quad;
};

/// The two triangles of quad q along the diagonal whose triangles' normals agree more.
void split_quad(const QuadSurface& s, int32_t q, std::vector<Triangle>& out) {
  const Quad& f = s.quads[q];
  auto normal = [&](int a, int b, int c) {
    return (s.points[f[b]] - s.points[f[a]]).cross(s.points[f[c]] - s.points[f[a]]);
  };
  auto agreement = [](const Vec3& m, const Vec3& n) {
    const double d = m.norm() * n.norm();
    return d > 0.0 ? m.dot(n) / d : -2.0;
  };
  const bool diag02 = agreement(normal(0, 1, 2), normal(0, 2, 3)) >=
                      agreement(normal(1, 2, 3), normal(1, 3, 0));
  const int k = diag02 ? 0 : 1;
  for (const std::array<int, 3>& c : {std::array<int, 3>{k, k + 1, k + 2},
                                      std::array<int, 3>{k, k + 2, (k + 3) & 3}}) {
    const Vec3 n = normal(c[0], c[1], c[2]);
    const double e = std::max({(s.points[f[c[1]]] - s.points[f[c[0]]]).squaredNorm(),
                               (s.points[f[c[2]]] - s.points[f[c[1]]]).squaredNorm(),
                               (s.points[f[c[0]]] - s.points[f[c[2]]]).squaredNorm()});
    if (!(n.norm() > kRelTol * e)) continue;  // degenerate: covered by its quad's other triangle
    out.push_back({{f[c[0]], f[c[1]], f[c[2]]}, q});
  }
}

/// Whether triangles a and b (of different quads) meet other than where they share vertices.
bool triangles_meet(const QuadSurface& s, const Triangle& a, const Triangle& b) {
  int shared = 0, ia = -1, ib = -1;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (a.v[i] == b.v[j]) {
        ++shared;
        ia = i;
        ib = j;
      }
  if (shared >= 2) return false;  // neighbours across an edge
  const std::array<Vec3, 3> pa{s.points[a.v[0]], s.points[a.v[1]], s.points[a.v[2]]};
  const std::array<Vec3, 3> pb{s.points[b.v[0]], s.points[b.v[1]], s.points[b.v[2]]};
  if (shared == 1)
    return segment_meets_triangle(pa[(ia + 1) % 3], pa[(ia + 2) % 3], pb) ||
           segment_meets_triangle(pb[(ib + 1) % 3], pb[(ib + 2) % 3], pa);
  for (int k = 0; k < 3; ++k)
    if (segment_meets_triangle(pa[k], pa[(k + 1) % 3], pb) ||
        segment_meets_triangle(pb[k], pb[(k + 1) % 3], pa))
      return true;
  return false;
}

}  // namespace

SelfIntersections find_self_intersections(const QuadSurface& s, int32_t max_pairs) {
  SelfIntersections out;
  std::vector<Triangle> tris;
  tris.reserve(2 * static_cast<size_t>(s.num_quads()));
  for (int32_t q = 0; q < s.num_quads(); ++q) split_quad(s, q, tris);
  if (tris.size() < 2) return out;

  // Grid: cells about two mean edge lengths wide, at most ~1024 along the bounding box.
  Vec3 lo = s.points[tris[0].v[0]], hi = lo;
  double edge_sum = 0.0;
  std::vector<Vec3> box_lo(tris.size()), box_hi(tris.size());
  for (size_t t = 0; t < tris.size(); ++t) {
    box_lo[t] = box_hi[t] = s.points[tris[t].v[0]];
    for (int k = 0; k < 3; ++k) {
      const Vec3& p = s.points[tris[t].v[k]];
      box_lo[t] = box_lo[t].cwiseMin(p);
      box_hi[t] = box_hi[t].cwiseMax(p);
      edge_sum += (s.points[tris[t].v[(k + 1) % 3]] - p).norm();
    }
    lo = lo.cwiseMin(box_lo[t]);
    hi = hi.cwiseMax(box_hi[t]);
  }
  const double diagonal = (hi - lo).norm();
  if (!(diagonal > 0.0)) return out;
  const double cell = std::max(2.0 * edge_sum / (3.0 * static_cast<double>(tris.size())), diagonal / 1024.0);
  auto cell_of = [&](const Vec3& p) {
    std::array<int64_t, 3> c;
    for (int k = 0; k < 3; ++k)
      c[k] = std::clamp<int64_t>(static_cast<int64_t>(std::floor((p[k] - lo[k]) / cell)), 0, 2047);
    return c;
  };
  auto key = [](const std::array<int64_t, 3>& c) { return (c[0] << 22) | (c[1] << 11) | c[2]; };

  std::vector<std::pair<int64_t, int32_t>> entries;
  entries.reserve(2 * tris.size());
  for (size_t t = 0; t < tris.size(); ++t) {
    const auto a = cell_of(box_lo[t]), b = cell_of(box_hi[t]);
    for (int64_t x = a[0]; x <= b[0]; ++x)
      for (int64_t y = a[1]; y <= b[1]; ++y)
        for (int64_t z = a[2]; z <= b[2]; ++z) entries.push_back({key({x, y, z}), static_cast<int32_t>(t)});
  }
  std::sort(entries.begin(), entries.end());

  std::vector<std::pair<int32_t, int32_t>> found;
  for (size_t i = 0; i < entries.size();) {
    size_t j = i;
    while (j < entries.size() && entries[j].first == entries[i].first) ++j;
    for (size_t m = i; m < j; ++m)
      for (size_t n = m + 1; n < j; ++n) {
        const int32_t ta = entries[m].second, tb = entries[n].second;
        if (tris[ta].quad == tris[tb].quad) continue;
        // Boxes must overlap, and the pair is tested in one cell only: its overlap's low corner's.
        const Vec3 olo = box_lo[ta].cwiseMax(box_lo[tb]), ohi = box_hi[ta].cwiseMin(box_hi[tb]);
        if ((olo.array() > ohi.array()).any() || key(cell_of(olo)) != entries[i].first) continue;
        ++out.tested;
        if (triangles_meet(s, tris[ta], tris[tb]))
          found.push_back({std::min(tris[ta].quad, tris[tb].quad), std::max(tris[ta].quad, tris[tb].quad)});
      }
    i = j;
  }
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  out.total = static_cast<int64_t>(found.size());
  if (static_cast<int64_t>(found.size()) > max_pairs) found.resize(std::max<int32_t>(max_pairs, 0));
  out.pairs = std::move(found);
  return out;
}

}  // namespace hexpeel
