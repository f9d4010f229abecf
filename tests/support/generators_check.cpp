// Checks and derived data for generated surfaces: manifold/Euler checks of polygon sets, the hex
// complex check (face use, vertex links, Euler characteristic), boundary extraction with
// boundary-first renumbering, and a chord walker.
//
// Independent of src/topology on purpose: the generators are the ground truth the topology code
// is tested against. Assumes nothing about its input (every check reports instead of asserting);
// the only exceptions are from_hex_mesh and boundary_quads, which expect vertex ids in range.
#include "support/generators_internal.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <numeric>

namespace hexpeel::testing {
namespace {

struct UnionFind {
  std::vector<int32_t> parent;
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int32_t find(int32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(int32_t a, int32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

/// The quad rotated so its smallest id comes first (orientation kept).
Quad normalized(const Quad& q) {
  int r = static_cast<int>(std::min_element(q.begin(), q.end()) - q.begin());
  return {q[r], q[(r + 1) & 3], q[(r + 2) & 3], q[(r + 3) & 3]};
}

std::string str(int64_t x) { return std::to_string(x); }

/// (key, id) lexicographic order, written out: std::tie/<=> are slow in unoptimized builds.
bool key_less(const Quad& a, int32_t ia, const Quad& b, int32_t ib) {
  for (int i = 0; i < 4; ++i)
    if (a[i] != b[i]) return a[i] < b[i];
  return ia < ib;
}

}  // namespace

namespace detail {

std::string check_polygons(const std::vector<int32_t>& corners, int arity, bool closed, int euler) {
  const int32_t nc = static_cast<int32_t>(corners.size());
  const int32_t nf = nc / arity;
  if (nf == 0) return "no polygons";
  // Compact vertex numbering (link triangles use global ids).
  std::vector<int32_t> verts(corners);
  std::sort(verts.begin(), verts.end());
  verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
  auto local = [&](int32_t v) {
    return static_cast<int32_t>(std::lower_bound(verts.begin(), verts.end(), v) - verts.begin());
  };
  auto next = [&](int32_t c) { return c - c % arity + (c % arity + 1) % arity; };

  struct Item {
    int32_t lo, hi, c;  // undirected edge and the corner where its half-edge starts
  };
  std::vector<Item> items;
  items.reserve(nc);
  for (int32_t c = 0; c < nc; ++c) {
    for (int32_t c2 = c - c % arity; c2 < c; ++c2)
      if (corners[c2] == corners[c])
        return "polygon " + str(c / arity) + " repeats vertex " + str(corners[c]);
    const int32_t a = corners[c], b = corners[next(c)];
    items.push_back({std::min(a, b), std::max(a, b), c});
  }
  std::sort(items.begin(), items.end(), [](const Item& x, const Item& y) {
    if (x.lo != y.lo) return x.lo < y.lo;
    return x.hi != y.hi ? x.hi < y.hi : x.c < y.c;
  });

  UnionFind faces(nf), fans(nc);
  std::vector<int32_t> boundary_at(verts.size(), 0);
  int64_t edges = 0;
  auto corner_of = [&](int32_t c, int32_t v) { return corners[c] == v ? c : next(c); };
  for (size_t i = 0; i < items.size();) {
    size_t j = i;
    while (j < items.size() && items[j].lo == items[i].lo && items[j].hi == items[i].hi) ++j;
    const Item& e = items[i];
    auto name = [&e] { return "edge (" + str(e.lo) + "," + str(e.hi) + ")"; };
    ++edges;
    if (j - i > 2) return name() + " is in " + str(static_cast<int64_t>(j - i)) + " polygons";
    if (j - i == 1) {
      if (closed) return name() + " is in one polygon only (polygon " + str(e.c / arity) + ")";
      ++boundary_at[local(e.lo)];
      ++boundary_at[local(e.hi)];
    } else {
      const int32_t c1 = items[i].c, c2 = items[i + 1].c;
      if (corners[c1] == corners[c2])
        return name() + " is traversed in the same direction by polygons " + str(c1 / arity) +
               " and " + str(c2 / arity);
      faces.unite(c1 / arity, c2 / arity);
      fans.unite(corner_of(c1, e.lo), corner_of(c2, e.lo));
      fans.unite(corner_of(c1, e.hi), corner_of(c2, e.hi));
    }
    i = j;
  }
  // Each vertex: its corners form one fan, which is a cycle or a path.
  std::vector<std::pair<int32_t, int32_t>> fan_of;
  fan_of.reserve(nc);
  for (int32_t c = 0; c < nc; ++c) fan_of.emplace_back(corners[c], fans.find(c));
  std::sort(fan_of.begin(), fan_of.end());
  fan_of.erase(std::unique(fan_of.begin(), fan_of.end()), fan_of.end());
  for (size_t i = 1; i < fan_of.size(); ++i)
    if (fan_of[i].first == fan_of[i - 1].first)
      return "vertex " + str(fan_of[i].first) + " has several polygon fans (non-manifold)";
  for (size_t v = 0; v < verts.size(); ++v)
    if (boundary_at[v] != 0 && boundary_at[v] != 2)
      return "vertex " + str(verts[v]) + " has " + str(boundary_at[v]) + " boundary edges";
  for (int32_t f = 1; f < nf; ++f)
    if (faces.find(f) != 0) return "polygons 0 and " + str(f) + " are in different components";
  const int64_t chi = static_cast<int64_t>(verts.size()) - edges + nf;
  if (chi != euler) return "V - E + F = " + str(chi) + ", expected " + str(euler);
  return "";
}

std::vector<Quad> boundary_quads(const HexMesh& mesh, std::string* error) {
  struct Item {
    Quad key;
    int32_t facet;  // 6*h + lf
  };
  std::vector<Item> items;
  items.reserve(6 * mesh.hexes.size());
  for (int32_t h = 0; h < mesh.num_hexes(); ++h)
    for (int lf = 0; lf < 6; ++lf) {
      Quad key;
      for (int i = 0; i < 4; ++i) key[i] = mesh.hexes[h][kHexFaces[lf][i]];
      std::sort(key.begin(), key.end());
      items.push_back({key, 6 * h + lf});
    }
  std::sort(items.begin(), items.end(), [](const Item& a, const Item& b) {
    return key_less(a.key, a.facet, b.key, b.facet);
  });
  std::vector<int32_t> once;
  for (size_t i = 0; i < items.size();) {
    size_t j = i;
    while (j < items.size() && items[j].key == items[i].key) ++j;
    if (j - i == 1) once.push_back(items[i].facet);
    if (j - i > 2 && error && error->empty())
      *error = "face of hex " + str(items[i].facet / 6) + " is used by " +
               str(static_cast<int64_t>(j - i)) + " hexes";
    i = j;
  }
  std::sort(once.begin(), once.end());
  std::vector<Quad> quads;
  quads.reserve(once.size());
  for (int32_t facet : once) {
    const Hex& hex = mesh.hexes[facet / 6];
    const auto& lf = kHexFaces[facet % 6];
    quads.push_back({hex[lf[0]], hex[lf[1]], hex[lf[2]], hex[lf[3]]});
  }
  return quads;
}

std::string check_hex_complex(const HexMesh& mesh, const std::vector<int32_t>* link_vertices) {
  const int32_t np = mesh.num_points(), nh = mesh.num_hexes();
  if (nh == 0) return "no hexes";
  std::vector<uint8_t> used(np, 0);
  for (int32_t h = 0; h < nh; ++h) {
    for (int32_t v : mesh.hexes[h]) {
      if (v < 0 || v >= np) return "hex " + str(h) + " has vertex id " + str(v) + " out of range";
      used[v] = 1;
    }
    Hex sorted = mesh.hexes[h];
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
      return "hex " + str(h) + " repeats a vertex";
  }
  for (int32_t v = 0; v < np; ++v)
    if (!used[v]) return "vertex " + str(v) + " is used by no hex";

  // Faces: used once (boundary) or twice with opposite orientations.
  struct Item {
    Quad key;
    int32_t facet;
  };
  std::vector<Item> items;
  items.reserve(6 * static_cast<size_t>(nh));
  auto face_of = [&](int32_t facet) {
    const Hex& hex = mesh.hexes[facet / 6];
    const auto& lf = kHexFaces[facet % 6];
    return Quad{hex[lf[0]], hex[lf[1]], hex[lf[2]], hex[lf[3]]};
  };
  for (int32_t facet = 0; facet < 6 * nh; ++facet) {
    Quad key = face_of(facet);
    std::sort(key.begin(), key.end());
    items.push_back({key, facet});
  }
  std::sort(items.begin(), items.end(), [](const Item& a, const Item& b) {
    return key_less(a.key, a.facet, b.key, b.facet);
  });
  int64_t num_faces = 0;
  std::vector<int32_t> boundary_corners;
  std::vector<uint8_t> on_boundary(np, 0);
  for (size_t i = 0; i < items.size();) {
    size_t j = i;
    while (j < items.size() && items[j].key == items[i].key) ++j;
    ++num_faces;
    auto hex_name = [&] {
      return "hex " + str(items[i].facet / 6) + " face " + str(items[i].facet % 6);
    };
    if (j - i > 2)
      return hex_name() + " is shared by " + str(static_cast<int64_t>(j - i)) + " hexes";
    const Quad a = normalized(face_of(items[i].facet));
    if (j - i == 1) {
      for (int32_t v : a) {
        boundary_corners.push_back(v);
        on_boundary[v] = 1;
      }
    } else {
      const Quad b = normalized(face_of(items[i + 1].facet));
      if (b != Quad{a[0], a[3], a[2], a[1]})
        return hex_name() + " and hex " + str(items[i + 1].facet / 6) +
               " share a face with the same orientation";
    }
    i = j;
  }
  if (std::string e = check_polygons(boundary_corners, 4, true, 2); !e.empty())
    return "boundary surface: " + e;

  std::vector<int64_t> edges;  // lo * 2^32 + hi
  edges.reserve(12 * static_cast<size_t>(nh));
  for (const Hex& hex : mesh.hexes)
    for (const auto& e : kHexEdges)
      edges.push_back((static_cast<int64_t>(std::min(hex[e[0]], hex[e[1]])) << 32) +
                      std::max(hex[e[0]], hex[e[1]]));
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  const int64_t chi = static_cast<int64_t>(np) - static_cast<int64_t>(edges.size()) + num_faces -
                      nh;
  if (chi != 1) return "V - E + F - H = " + str(chi) + ", expected 1";

  // Vertex links: one triangle per incident hex corner, from the corner frames.
  std::vector<int32_t> start(np + 1, 0);
  for (const Hex& hex : mesh.hexes)
    for (int32_t v : hex) ++start[v + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<int32_t> slot(start.begin(), start.end() - 1), tris(3 * 8 * static_cast<size_t>(nh));
  for (const Hex& hex : mesh.hexes)
    for (int c = 0; c < 8; ++c) {
      const int32_t s = slot[hex[c]]++;
      for (int i = 0; i < 3; ++i) tris[3 * s + i] = hex[kHexCornerFrames[c][i]];
    }
  std::vector<int32_t> all;
  if (!link_vertices) {
    all.resize(np);
    std::iota(all.begin(), all.end(), 0);
  }
  for (int32_t v : link_vertices ? *link_vertices : all) {
    std::vector<int32_t> link(tris.begin() + 3 * start[v], tris.begin() + 3 * start[v + 1]);
    if (std::string e = check_polygons(link, 3, !on_boundary[v], on_boundary[v] ? 1 : 2);
        !e.empty())
      return "link of vertex " + str(v) + (on_boundary[v] ? " (boundary)" : " (interior)") +
             " is not a " + (on_boundary[v] ? "disk: " : "sphere: ") + e;
  }
  return "";
}

Generated from_hex_mesh(std::string name, const HexMesh& mesh) {
  Generated g;
  g.name = std::move(name);
  const std::vector<Quad> quads = boundary_quads(mesh);
  std::vector<int32_t> new_id(mesh.points.size(), -1);
  int32_t n = 0;
  for (const Quad& q : quads)
    for (int32_t v : q)
      if (new_id[v] < 0) new_id[v] = n++;
  const int32_t nb = n;
  for (const Hex& hex : mesh.hexes)
    for (int32_t v : hex)
      if (new_id[v] < 0) new_id[v] = n++;
  g.known_mesh.points.resize(n);
  for (size_t v = 0; v < mesh.points.size(); ++v)
    if (new_id[v] >= 0) g.known_mesh.points[new_id[v]] = mesh.points[v];
  g.known_mesh.hexes.reserve(mesh.hexes.size());
  for (const Hex& hex : mesh.hexes) {
    Hex h;
    for (int c = 0; c < 8; ++c) h[c] = new_id[hex[c]];
    g.known_mesh.hexes.push_back(h);
  }
  g.surface.points.assign(g.known_mesh.points.begin(), g.known_mesh.points.begin() + nb);
  g.surface.quads.reserve(quads.size());
  for (const Quad& q : quads)
    g.surface.quads.push_back({new_id[q[0]], new_id[q[1]], new_id[q[2]], new_id[q[3]]});
  g.chord_lengths = chord_lengths_of(g.surface);
  g.chords = static_cast<int32_t>(g.chord_lengths.size());
  return g;
}

}  // namespace detail

std::string check_surface(const QuadSurface& surface) {
  const int32_t np = surface.num_points();
  std::vector<uint8_t> used(np, 0);
  std::vector<int32_t> corners;
  corners.reserve(4 * surface.quads.size());
  for (int32_t q = 0; q < surface.num_quads(); ++q)
    for (int32_t v : surface.quads[q]) {
      if (v < 0 || v >= np) return "quad " + str(q) + " has vertex id " + str(v) + " out of range";
      used[v] = 1;
      corners.push_back(v);
    }
  for (int32_t v = 0; v < np; ++v)
    if (!used[v]) return "vertex " + str(v) + " is used by no quad";
  return detail::check_polygons(corners, 4, true, 2);
}

std::string check_known_mesh(const Generated& g) {
  if (std::string e = check_surface(g.surface); !e.empty()) return "surface: " + e;
  const HexMesh& mesh = g.known_mesh;
  if (mesh.points.size() < g.surface.points.size())
    return "known_mesh has fewer points than the surface";
  for (int32_t v = 0; v < g.surface.num_points(); ++v)
    if (mesh.points[v] != g.surface.points[v])
      return "known_mesh point " + str(v) + " differs from the surface point";
  if (std::string e = detail::check_hex_complex(mesh); !e.empty()) return "known_mesh: " + e;
  std::vector<Quad> a = detail::boundary_quads(mesh), b = g.surface.quads;
  for (Quad& q : a) q = normalized(q);
  for (Quad& q : b) q = normalized(q);
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  if (a != b) {
    std::vector<Quad> only_mesh, only_surface;
    std::set_difference(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(only_mesh));
    std::set_difference(b.begin(), b.end(), a.begin(), a.end(), std::back_inserter(only_surface));
    return "known_mesh boundary differs from the surface: " + str(only_mesh.size()) +
           " boundary faces not in the surface, " + str(only_surface.size()) +
           " surface quads not on the boundary";
  }
  if (g.chords >= 0) {
    if (g.chords != static_cast<int32_t>(g.chord_lengths.size()))
      return "chords != chord_lengths.size()";
    if (g.chord_lengths != chord_lengths_of(g.surface))
      return "chord_lengths differ from the chords walked on the surface";
  }
  return "";
}

std::vector<int32_t> chord_lengths_of(const QuadSurface& surface) {
  const QuadAdjacency adj = build_adjacency(surface);
  const int32_t nq = surface.num_quads();
  std::vector<uint8_t> visited(2 * static_cast<size_t>(nq), 0);  // (quad, edge parity)
  std::vector<int32_t> lengths;
  for (int32_t q0 = 0; q0 < nq; ++q0)
    for (int d = 0; d < 2; ++d) {
      int32_t q = q0, k = d, len = 0;  // entering quad q through its edge k
      while (!visited[2 * q + (k & 1)]) {
        visited[2 * q + (k & 1)] = 1;
        ++len;
        const int32_t opp = adj.opposite[4 * q + ((k + 2) & 3)];
        if (opp < 0) return {};
        q = opp / 4;
        k = opp % 4;
      }
      if (len > 0) lengths.push_back(len);
    }
  std::sort(lengths.begin(), lengths.end());
  return lengths;
}

bool hex_is_positive(const HexMesh& mesh, int32_t h) {
  // Plain doubles rather than Eigen expressions: this runs in inner loops of unoptimized builds.
  const Hex& hex = mesh.hexes[h];
  for (int c = 0; c < 8; ++c) {
    const double* p = mesh.points[hex[c]].data();
    double e[3][3];
    for (int i = 0; i < 3; ++i) {
      const double* q = mesh.points[hex[kHexCornerFrames[c][i]]].data();
      for (int k = 0; k < 3; ++k) e[i][k] = q[k] - p[k];
    }
    const double det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                       e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                       e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
    if (!(det > 0.0)) return false;
  }
  return true;
}

int32_t count_positive_hexes(const HexMesh& mesh) {
  int32_t n = 0;
  for (int32_t h = 0; h < mesh.num_hexes(); ++h) n += hex_is_positive(mesh, h) ? 1 : 0;
  return n;
}

}  // namespace hexpeel::testing
