// Hexes by way of tetrahedra (tet_fill.h).
//
// refine_surface's six-split of quad q makes, for each triangle t (corners A, B, C in quad order),
// the quads 6q+3t+0 = [A, m_AB, g, m_CA], 6q+3t+1 = [B, m_BC, g, m_AB], 6q+3t+2 = [C, m_CA, g,
// m_BC] (m = edge midpoints, the diagonal's being the quad's centre; g = the centroid). A tet
// split's hex at corner A of a boundary face ABC has exactly the face [A, m_AB, g_ABC, m_CA]
// there, so the split's boundary vertices are named by the refined surface's ids and its
// boundary is that surface. Positions: boundary vertices as `refined` has them (on the input
// quads' patches), interior ones as the tet split puts them (midpoints, centroids).
#include "hexpeel/tet_fill.h"

#include "hexpeel/surface_repair.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <map>
#include <mutex>
#include <string>
#include <type_traits>

#ifdef HEXPEEL_HAVE_GMSH
#include <dlfcn.h>
#endif

namespace hexpeel {

#ifndef HEXPEEL_HAVE_GMSH

bool tet_fill_available() { return false; }

TetFill tet_fill(const QuadSurface&, const QuadSurface&) {
  TetFill out;
  out.status = Status::error(StatusCode::stuck,
                             "this build has no tetrahedralizer (gmsh's C API, Debian "
                             "libgmsh-dev) for the repair's fill through tetrahedra");
  return out;
}

#else

namespace {

std::mutex gmsh_mutex;  // gmsh keeps one global model

/// gmsh's C API (gmshc.h, 4.8), loaded from its shared library the first time the fill is
/// needed, so that hexpeel starts without it and runs where it is missing (the fill then says
/// so). Every function reports errors through its last argument.
struct GmshApi {
  void (*initialize)(int, char**, const int, int*) = nullptr;
  void (*finalize)(int*) = nullptr;
  void (*set_number)(const char*, const double, int*) = nullptr;
  void (*model_add)(const char*, int*) = nullptr;
  int (*add_discrete_entity)(const int, const int, int*, size_t, int*) = nullptr;
  void (*add_nodes)(const int, const int, size_t*, size_t, double*, size_t, double*, size_t, int*) = nullptr;
  void (*add_elements_by_type)(const int, const int, size_t*, size_t, size_t*, size_t, int*) = nullptr;
  int (*add_surface_loop)(int*, size_t, const int, int*) = nullptr;
  int (*add_volume)(int*, size_t, const int, int*) = nullptr;
  void (*synchronize)(int*) = nullptr;
  void (*generate)(const int, int*) = nullptr;
  void (*get_nodes)(size_t**, size_t*, double**, size_t*, double**, size_t*, const int, const int,
                    const int, const int, int*) = nullptr;
  void (*get_elements_by_type)(const int, size_t**, size_t*, size_t**, size_t*, const int,
                               const size_t, const size_t, int*) = nullptr;
  void (*free)(void*) = nullptr;
  void (*last_error)(char**, int*) = nullptr;
  bool loaded = false;
};

/// The API, loaded once (never unloaded); `loaded` false when the library or a symbol is missing.
const GmshApi& gmsh_api() {
  static const GmshApi api = [] {
    GmshApi a;
    void* lib = dlopen("libgmsh.so.4.8", RTLD_NOW | RTLD_LOCAL);
    if (lib == nullptr) lib = dlopen("libgmsh.so", RTLD_NOW | RTLD_LOCAL);
    if (lib == nullptr) return a;
    bool ok = true;
    auto sym = [&](auto& f, const char* name) {
      f = reinterpret_cast<std::remove_reference_t<decltype(f)>>(dlsym(lib, name));
      ok = ok && f != nullptr;
    };
    sym(a.initialize, "gmshInitialize");
    sym(a.finalize, "gmshFinalize");
    sym(a.set_number, "gmshOptionSetNumber");
    sym(a.model_add, "gmshModelAdd");
    sym(a.add_discrete_entity, "gmshModelAddDiscreteEntity");
    sym(a.add_nodes, "gmshModelMeshAddNodes");
    sym(a.add_elements_by_type, "gmshModelMeshAddElementsByType");
    sym(a.add_surface_loop, "gmshModelGeoAddSurfaceLoop");
    sym(a.add_volume, "gmshModelGeoAddVolume");
    sym(a.synchronize, "gmshModelGeoSynchronize");
    sym(a.generate, "gmshModelMeshGenerate");
    sym(a.get_nodes, "gmshModelMeshGetNodes");
    sym(a.get_elements_by_type, "gmshModelMeshGetElementsByType");
    sym(a.free, "gmshFree");
    sym(a.last_error, "gmshLoggerGetLastError");
    a.loaded = ok;
    return a;
  }();
  return api;
}

using Tri = std::array<int32_t, 3>;

/// The input triangles of every quad, as refine_surface splits it, with the refined ids of their
/// edge midpoints and centroid.
struct BoundaryTriangle {
  Tri corners;              ///< input vertex ids, outward
  std::array<int32_t, 3> mid;  ///< refined ids of m_AB, m_BC, m_CA
  int32_t centroid = -1;    ///< refined id of g
};

std::vector<BoundaryTriangle> boundary_triangles(const QuadSurface& s, const QuadSurface& refined) {
  std::vector<BoundaryTriangle> out;
  out.reserve(2 * s.quads.size());
  for (int32_t q = 0; q < s.num_quads(); ++q) {
    const Quad& f = s.quads[q];
    const int r = six_split_diagonal(s, q);
    for (int t = 0; t < 2; ++t) {
      const int a = (r + 2 * t) % 4;
      const Quad& qa = refined.quads[6 * q + 3 * t];
      const Quad& qb = refined.quads[6 * q + 3 * t + 1];
      BoundaryTriangle b;
      b.corners = {f[a], f[(a + 1) % 4], f[(a + 2) % 4]};
      b.mid = {qa[1], qb[1], qa[3]};
      b.centroid = qa[2];
      out.push_back(b);
    }
  }
  return out;
}

Tri sorted(Tri t) {
  std::sort(t.begin(), t.end());
  return t;
}

/// Tetrahedra of the solid bounded by the triangles, over the input points (ids kept) and the
/// points the tetrahedralization adds (appended to `points`).
Status tetrahedralize(const std::vector<Vec3>& in_points, const std::vector<BoundaryTriangle>& tris,
                      std::vector<Vec3>& points, std::vector<std::array<int32_t, 4>>& tets) {
  const GmshApi& g = gmsh_api();
  if (!g.loaded) return Status::error(StatusCode::stuck, "gmsh's library (libgmsh.so.4.8) cannot be loaded");
  const std::lock_guard<std::mutex> lock(gmsh_mutex);
  int err = 0;
  g.initialize(0, nullptr, 0, &err);
  if (err) return Status::error(StatusCode::stuck, "gmsh's library did not initialize");
  // The first error decides; later calls are skipped.
  std::string failure;
  auto check = [&](const char* what) {
    if (err == 0 || !failure.empty()) return failure.empty();
    char* msg = nullptr;
    int e2 = 0;
    g.last_error(&msg, &e2);
    failure = std::string(what) + (msg != nullptr && *msg ? std::string(": ") + msg : std::string());
    if (msg != nullptr) g.free(msg);
    return false;
  };
  g.set_number("General.Terminal", 0, &err);
  g.set_number("General.Verbosity", 0, &err);
  g.set_number("General.NumThreads", 1, &err);
  g.set_number("Mesh.Algorithm3D", 1, &err);  // Delaunay
  g.set_number("Mesh.Optimize", 0, &err);     // measured both ways: see docs/benchmarks.md
  check("options");
  if (failure.empty()) g.model_add("hexpeel_tet_fill", &err);
  int surf = -1;
  if (check("model")) surf = g.add_discrete_entity(2, -1, nullptr, 0, &err);
  std::vector<std::size_t> tags(in_points.size());
  std::vector<double> coord(3 * in_points.size());
  for (size_t i = 0; i < in_points.size(); ++i) {
    tags[i] = i + 1;
    for (int k = 0; k < 3; ++k) coord[3 * i + k] = in_points[i][k];
  }
  if (check("surface")) g.add_nodes(2, surf, tags.data(), tags.size(), coord.data(), coord.size(), nullptr, 0, &err);
  std::vector<std::size_t> elem(tris.size()), nodes(3 * tris.size());
  for (size_t i = 0; i < tris.size(); ++i) {
    elem[i] = i + 1;
    for (int k = 0; k < 3; ++k) nodes[3 * i + k] = static_cast<std::size_t>(tris[i].corners[k]) + 1;
  }
  if (check("nodes")) g.add_elements_by_type(surf, 2, elem.data(), elem.size(), nodes.data(), nodes.size(), &err);
  int loop = -1;
  if (check("triangles")) loop = g.add_surface_loop(&surf, 1, -1, &err);
  if (check("surface loop")) g.add_volume(&loop, 1, -1, &err);
  if (check("volume")) g.synchronize(&err);
  if (check("synchronize")) g.generate(3, &err);
  size_t *all_tags = nullptr, *tet_tags = nullptr, *tet_nodes = nullptr;
  double *all_coord = nullptr, *param = nullptr;
  size_t n_tags = 0, n_coord = 0, n_param = 0, n_tets = 0, n_tet_nodes = 0;
  if (check("tetrahedralization failed"))
    g.get_nodes(&all_tags, &n_tags, &all_coord, &n_coord, &param, &n_param, -1, -1, 0, 0, &err);
  if (check("nodes of the tetrahedra"))
    g.get_elements_by_type(4, &tet_tags, &n_tets, &tet_nodes, &n_tet_nodes, -1, 0, 1, &err);
  if (check("tetrahedra")) {
    std::map<std::size_t, int32_t> id_of;
    points = in_points;
    for (size_t i = 0; i < n_tags; ++i) {
      if (all_tags[i] <= in_points.size()) {
        id_of[all_tags[i]] = static_cast<int32_t>(all_tags[i] - 1);
        continue;
      }
      id_of[all_tags[i]] = static_cast<int32_t>(points.size());
      points.emplace_back(all_coord[3 * i], all_coord[3 * i + 1], all_coord[3 * i + 2]);
    }
    tets.resize(n_tets);
    for (size_t i = 0; i < n_tets && failure.empty(); ++i)
      for (int k = 0; k < 4; ++k) {
        const auto it = id_of.find(tet_nodes[4 * i + k]);
        if (it == id_of.end()) {
          failure = "a tetrahedron refers to a node gmsh did not return";
          break;
        }
        tets[i][k] = it->second;
      }
  }
  for (void* p : {static_cast<void*>(all_tags), static_cast<void*>(all_coord), static_cast<void*>(param),
                  static_cast<void*>(tet_tags), static_cast<void*>(tet_nodes)})
    if (p != nullptr) g.free(p);
  g.finalize(&err);
  if (!failure.empty()) return Status::error(StatusCode::stuck, "tetrahedralization failed: " + failure);
  if (tets.empty()) return Status::error(StatusCode::stuck, "the tetrahedralization made no tetrahedra");
  return Status::success();
}

}  // namespace

bool tet_fill_available() { return gmsh_api().loaded; }

TetFill tet_fill(const QuadSurface& surface, const QuadSurface& refined) {
  const auto t0 = std::chrono::steady_clock::now();
  TetFill out;
  if (refined.num_quads() != 6 * surface.num_quads()) {
    out.status = Status::error(StatusCode::internal_error, "tet_fill: the refined surface is not the six-split");
    return out;
  }
  const std::vector<BoundaryTriangle> tris = boundary_triangles(surface, refined);
  std::vector<Vec3> pts;
  std::vector<std::array<int32_t, 4>> tets;
  out.status = tetrahedralize(surface.points, tris, pts, tets);
  if (!out.status.ok()) return out;
  out.stats.tetrahedra = static_cast<int32_t>(tets.size());
  out.stats.interior_nodes = static_cast<int32_t>(pts.size() - surface.points.size());

  // Orient every tetrahedron positively; a flat one cannot be split into positive hexes.
  for (auto& t : tets) {
    const double det = (pts[t[1]] - pts[t[0]]).dot((pts[t[2]] - pts[t[0]]).cross(pts[t[3]] - pts[t[0]]));
    if (det < 0) std::swap(t[2], t[3]);
    if (det == 0) {
      out.status = Status::error(StatusCode::stuck, "the tetrahedralization has a flat tetrahedron");
      return out;
    }
  }
  // Its boundary must be the input's triangles, each once: no point added on the surface.
  std::map<Tri, int32_t> face_count;
  static const int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  for (const auto& t : tets)
    for (const auto& f : kFace) ++face_count[sorted({t[f[0]], t[f[1]], t[f[2]]})];
  std::map<Tri, int32_t> boundary_centroid;
  for (const BoundaryTriangle& b : tris) boundary_centroid[sorted(b.corners)] = b.centroid;
  size_t boundary_faces = 0;
  for (const auto& [key, n] : face_count) {
    if (n == 1) {
      ++boundary_faces;
      if (!boundary_centroid.count(key)) {
        out.status = Status::error(StatusCode::stuck,
                                   "the tetrahedralization changed the surface (a boundary face "
                                   "that is not an input triangle)");
        return out;
      }
    } else if (n != 2) {
      out.status = Status::error(StatusCode::stuck, "the tetrahedralization is not manifold");
      return out;
    }
  }
  if (boundary_faces != tris.size()) {
    out.status = Status::error(StatusCode::stuck, "the tetrahedralization lost surface triangles");
    return out;
  }

  // Vertex ids: the refined surface's first (boundary), then interior tet points, interior edge
  // midpoints, interior face centroids and tet centres, in order of first use.
  std::vector<Vec3>& P = out.points;
  P = refined.points;
  std::map<std::array<int32_t, 2>, int32_t> edge_mid;
  for (const BoundaryTriangle& b : tris)
    for (int k = 0; k < 3; ++k) {
      std::array<int32_t, 2> e{b.corners[k], b.corners[(k + 1) % 3]};
      std::sort(e.begin(), e.end());
      edge_mid[e] = b.mid[k];
    }
  const int32_t n_in = surface.num_points();
  std::vector<int32_t> tet_point(pts.size(), -1);  // tet point -> complex id
  for (int32_t v = 0; v < n_in; ++v) tet_point[v] = v;  // refined keeps the input ids first
  auto point_id = [&](int32_t v) {
    if (tet_point[v] < 0) {
      tet_point[v] = static_cast<int32_t>(P.size());
      P.push_back(pts[v]);
    }
    return tet_point[v];
  };
  auto mid_id = [&](int32_t a, int32_t b) {
    std::array<int32_t, 2> e{a, b};
    std::sort(e.begin(), e.end());
    auto [it, fresh] = edge_mid.emplace(e, -1);
    if (fresh) {
      it->second = static_cast<int32_t>(P.size());
      P.push_back(0.5 * (pts[a] + pts[b]));
    }
    return it->second;
  };
  std::map<Tri, int32_t> face_id = boundary_centroid;
  auto face_centroid = [&](int32_t a, int32_t b, int32_t c) {
    auto [it, fresh] = face_id.emplace(sorted({a, b, c}), -1);
    if (fresh) {
      it->second = static_cast<int32_t>(P.size());
      P.push_back((pts[a] + pts[b] + pts[c]) / 3.0);
    }
    return it->second;
  };
  // Corner i of a positive tet with the other three in an order that keeps it positive.
  static const int kCornerOrder[4][4] = {{0, 1, 2, 3}, {1, 0, 3, 2}, {2, 3, 0, 1}, {3, 2, 1, 0}};
  std::vector<Hex>& hexes = out.complex.hexes;
  hexes.reserve(4 * tets.size());
  for (const auto& t : tets) {
    const int32_t centre = static_cast<int32_t>(P.size());
    P.push_back(0.25 * (pts[t[0]] + pts[t[1]] + pts[t[2]] + pts[t[3]]));
    for (const auto& o : kCornerOrder) {
      const int32_t v0 = t[o[0]], v1 = t[o[1]], v2 = t[o[2]], v3 = t[o[3]];
      hexes.push_back({point_id(v0), mid_id(v0, v1), face_centroid(v0, v1, v2), mid_id(v0, v2),
                       mid_id(v0, v3), face_centroid(v0, v1, v3), centre, face_centroid(v0, v2, v3)});
    }
  }
  out.complex.num_vertices = static_cast<int32_t>(P.size());
  out.complex.input_vertex.assign(P.size(), -1);
  for (int32_t v = 0; v < refined.num_points(); ++v) out.complex.input_vertex[v] = v;
  out.complex.created_at.assign(P.size(), -1);
  out.stats.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

#endif

}  // namespace hexpeel
