// Topology of a hex complex: its faces and edges, Euler characteristic, singular edges, and a
// test that the complex is a combinatorial 3-ball.
//
// Faces are keyed by their sorted corner ids and edges by their sorted end points (the same
// identification the independent checker uses); both are found by sorting, so every count and
// every message is deterministic. The ball test checks that the complex is a 3-manifold with
// boundary (links of edges and vertices, as in any textbook on PL topology, e.g. Rourke and
// Sanderson, "Introduction to Piecewise-Linear Topology", ch. 2), that it is connected, that its
// boundary is one surface of Euler characteristic 2 (a sphere) and that the complex's own Euler
// characteristic is 1. Such a complex is a closed 3-manifold with one ball removed; it is a ball
// exactly when that manifold is the 3-sphere, which no count can decide (a punctured Poincare
// homology sphere passes every check here). That is as far as this test goes.
// Input: any HexMesh (ids are checked first). Output: ComplexTopology; never throws on bad input.
#include "quality_internal.h"

#include <algorithm>
#include <array>
#include <sstream>
#include <string>
#include <tuple>

namespace hexpeel::quality_detail {
namespace {

// Local edge joining local corners a and b, -1 if none.
constexpr int local_edge(int a, int b) {
  for (int e = 0; e < 12; ++e)
    if ((kHexEdges[e][0] == a && kHexEdges[e][1] == b) ||
        (kHexEdges[e][0] == b && kHexEdges[e][1] == a))
      return e;
  return -1;
}

// kFaceEdges[lf][i]: local edge from corner i to corner i+1 of local face lf.
constexpr std::array<std::array<int, 4>, 6> kFaceEdges = [] {
  std::array<std::array<int, 4>, 6> t{};
  for (int f = 0; f < 6; ++f)
    for (int i = 0; i < 4; ++i) t[f][i] = local_edge(kHexFaces[f][i], kHexFaces[f][(i + 1) % 4]);
  return t;
}();

// kEdgeFaces[le]: the two local faces containing local edge le.
constexpr std::array<std::array<int, 2>, 12> kEdgeFaces = [] {
  std::array<std::array<int, 2>, 12> t{};
  std::array<int, 12> n{};
  for (int f = 0; f < 6; ++f)
    for (int i = 0; i < 4; ++i) {
      const int e = kFaceEdges[f][i];
      if (e >= 0 && n[e] < 2) t[e][n[e]++] = f;
    }
  return t;
}();

constexpr bool tables_consistent() {
  std::array<int, 12> uses{};
  for (const auto& fe : kFaceEdges)
    for (int e : fe) {
      if (e < 0) return false;
      ++uses[e];
    }
  for (int u : uses)
    if (u != 2) return false;
  return true;
}
static_assert(tables_consistent(), "kHexFaces and kHexEdges disagree");

// Union-find with path halving; the smaller index becomes the root, so results never depend
// on the order of unions.
struct UnionFind {
  std::vector<int32_t> parent;
  void reset(size_t n) {
    parent.resize(n);
    for (size_t i = 0; i < n; ++i) parent[i] = static_cast<int32_t>(i);
  }
  int32_t find(int32_t x) {
    while (parent[x] != x) {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  }
  void unite(int32_t a, int32_t b) {
    a = find(a);
    b = find(b);
    if (a == b) return;
    if (a < b) std::swap(a, b);
    parent[a] = b;
  }
};

// A failed check: how often, and the first offender in words.
struct Finding {
  explicit Finding(const char* w) : what(w) {}
  const char* what;   // the check, in words
  int64_t count = 0;  // how many elements fail it
  std::string first;  // the first of them, with ids
};

template <class It>
std::string id_list(It begin, It end) {
  std::ostringstream s;
  s << '(';
  for (It it = begin; it != end; ++it) s << (it == begin ? "" : ", ") << *it;
  s << ')';
  return s.str();
}

struct FaceRec {
  std::array<int32_t, 4> key;  // sorted corner ids
  int32_t slot;                // 6*hex + local face
};

struct EdgeRec {
  int32_t lo, hi;  // sorted end points
  int32_t slot;    // 12*hex + local edge
};

struct LinkEdge {
  int32_t lo, hi;  // sorted link vertices (point ids)
  int32_t tri;     // triangle (= incidence) it comes from
};

}  // namespace

ComplexTopology analyze_topology(const HexMesh& mesh) {
  ComplexTopology t;
  const int32_t nh = mesh.num_hexes();
  const int32_t np = mesh.num_points();

  // Ids first: nothing below is meaningful (or safe) with a corner outside the point array.
  {
    Finding bad{"hex corners referring to no point"};
    for (int32_t h = 0; h < nh; ++h)
      for (int k = 0; k < 8; ++k) {
        const int32_t v = mesh.hexes[h][k];
        if ((v < 0 || v >= np) && bad.count++ == 0)
          bad.first = "hex " + std::to_string(h) + " corner " + std::to_string(k) + " is point " +
                      std::to_string(v) + " of " + std::to_string(np);
      }
    if (bad.count > 0) {
      t.ids_valid = false;
      t.message = std::string(bad.what) + ": " + std::to_string(bad.count) + " (first: " +
                  bad.first + ")";
      return t;
    }
  }
  if (nh == 0) {
    t.message = "the mesh has no hexes";
    return t;
  }

  Finding repeated{"hexes repeating a vertex"};
  Finding overused{"faces used by more than two hexes"};
  Finding bad_edge_link{"edges whose link is not a cycle (interior) or a path (boundary)"};
  Finding bad_vertex_link{"vertices whose link is not a sphere (interior) or a disk (boundary)"};

  std::vector<uint8_t> used(np, 0);
  for (int32_t h = 0; h < nh; ++h) {
    Hex s = mesh.hexes[h];
    for (int32_t v : s) used[v] = 1;
    std::sort(s.begin(), s.end());
    const auto dup = std::adjacent_find(s.begin(), s.end());
    if (dup != s.end() && repeated.count++ == 0)
      repeated.first = "hex " + std::to_string(h) + " uses point " + std::to_string(*dup) +
                       " twice";
  }
  t.vertices = static_cast<int32_t>(std::count(used.begin(), used.end(), 1));

  // Faces: sort the 6*nh hex faces by corner set; runs of equal keys are the faces.
  std::vector<FaceRec> frec;
  frec.reserve(6 * static_cast<size_t>(nh));
  for (int32_t h = 0; h < nh; ++h)
    for (int lf = 0; lf < 6; ++lf) {
      FaceRec r{};
      for (int i = 0; i < 4; ++i) r.key[i] = mesh.hexes[h][kHexFaces[lf][i]];
      std::sort(r.key.begin(), r.key.end());
      r.slot = 6 * h + lf;
      frec.push_back(r);
    }
  std::sort(frec.begin(), frec.end(), [](const FaceRec& a, const FaceRec& b) {
    return std::tie(a.key, a.slot) < std::tie(b.key, b.slot);
  });
  std::vector<int32_t> face_of(frec.size()), face_start;
  for (size_t i = 0; i < frec.size(); ++i) {
    if (i == 0 || frec[i].key != frec[i - 1].key) face_start.push_back(static_cast<int32_t>(i));
    face_of[frec[i].slot] = static_cast<int32_t>(face_start.size()) - 1;
  }
  face_start.push_back(static_cast<int32_t>(frec.size()));
  t.faces = static_cast<int32_t>(face_start.size()) - 1;
  auto face_uses = [&](int32_t f) { return face_start[f + 1] - face_start[f]; };
  for (int32_t f = 0; f < t.faces; ++f) {
    if (face_uses(f) <= 2) continue;
    if (overused.count++ == 0) {
      std::vector<int32_t> hexes;
      for (int32_t i = face_start[f]; i < face_start[f + 1]; ++i) hexes.push_back(frec[i].slot / 6);
      overused.first = "face " + id_list(frec[face_start[f]].key.begin(),
                                         frec[face_start[f]].key.end()) +
                       " used by hexes " + id_list(hexes.begin(), hexes.end());
    }
  }
  t.faces_manifold = overused.count == 0;

  // Edges, the same way.
  std::vector<EdgeRec> erec;
  erec.reserve(12 * static_cast<size_t>(nh));
  for (int32_t h = 0; h < nh; ++h)
    for (int le = 0; le < 12; ++le) {
      const int32_t a = mesh.hexes[h][kHexEdges[le][0]], b = mesh.hexes[h][kHexEdges[le][1]];
      erec.push_back({std::min(a, b), std::max(a, b), 12 * h + le});
    }
  std::sort(erec.begin(), erec.end(), [](const EdgeRec& a, const EdgeRec& b) {
    return std::tie(a.lo, a.hi, a.slot) < std::tie(b.lo, b.hi, b.slot);
  });
  std::vector<int32_t> edge_of(erec.size()), edge_start;
  for (size_t i = 0; i < erec.size(); ++i) {
    if (i == 0 || erec[i].lo != erec[i - 1].lo || erec[i].hi != erec[i - 1].hi)
      edge_start.push_back(static_cast<int32_t>(i));
    edge_of[erec[i].slot] = static_cast<int32_t>(edge_start.size()) - 1;
  }
  edge_start.push_back(static_cast<int32_t>(erec.size()));
  t.edges = static_cast<int32_t>(edge_start.size()) - 1;
  t.euler_characteristic = static_cast<int64_t>(t.vertices) - t.edges + t.faces - nh;

  // Boundary: faces used once, in hex-slot order, with their edges and vertices marked.
  std::vector<uint8_t> edge_on_boundary(t.edges, 0), vertex_on_boundary(np, 0);
  for (int32_t slot = 0; slot < 6 * nh; ++slot) {
    if (face_uses(face_of[slot]) != 1) continue;
    const int32_t h = slot / 6, lf = slot % 6;
    Quad q;
    for (int i = 0; i < 4; ++i) {
      q[i] = mesh.hexes[h][kHexFaces[lf][i]];
      vertex_on_boundary[q[i]] = 1;
      edge_on_boundary[edge_of[12 * h + kFaceEdges[lf][i]]] = 1;
    }
    t.boundary_quads.push_back(q);
    t.boundary_slots.push_back(slot);
  }
  t.boundary_faces = static_cast<int32_t>(t.boundary_quads.size());

  // Singular edges, and edge links: the graph whose nodes are the faces around the edge and
  // whose arcs are the hexes around it (each joins its two faces containing the edge) must be
  // one cycle (interior edge) or one path (boundary edge).
  std::vector<std::array<int32_t, 2>> arcs;
  std::vector<int32_t> nodes, degree;
  UnionFind uf;
  for (int32_t e = 0; e < t.edges; ++e) {
    const int32_t count = edge_start[e + 1] - edge_start[e];
    if (edge_on_boundary[e]) {
      if (count != 2) ++t.singular_edges_boundary;
    } else if (count != 4) {
      ++t.singular_edges_interior;
    }
    arcs.clear();
    nodes.clear();
    for (int32_t i = edge_start[e]; i < edge_start[e + 1]; ++i) {
      const int32_t h = erec[i].slot / 12, le = erec[i].slot % 12;
      const int32_t f0 = face_of[6 * h + kEdgeFaces[le][0]], f1 = face_of[6 * h + kEdgeFaces[le][1]];
      arcs.push_back({f0, f1});
      nodes.push_back(f0);
      nodes.push_back(f1);
    }
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
    degree.assign(nodes.size(), 0);
    uf.reset(nodes.size());
    bool ok = true;
    for (const auto& a : arcs) {
      const auto i0 = static_cast<int32_t>(std::lower_bound(nodes.begin(), nodes.end(), a[0]) - nodes.begin());
      const auto i1 = static_cast<int32_t>(std::lower_bound(nodes.begin(), nodes.end(), a[1]) - nodes.begin());
      ok = ok && i0 != i1;
      ++degree[i0];
      ++degree[i1];
      uf.unite(i0, i1);
    }
    int32_t ends = 0, roots = 0;
    for (size_t i = 0; i < nodes.size(); ++i) {
      ok = ok && (degree[i] == 1 || degree[i] == 2);
      ends += degree[i] == 1;
      roots += uf.find(static_cast<int32_t>(i)) == static_cast<int32_t>(i);
    }
    ok = ok && roots == 1 && ends == (edge_on_boundary[e] ? 2 : 0);
    if (!ok && bad_edge_link.count++ == 0) {
      std::vector<int32_t> hexes;
      for (int32_t i = edge_start[e]; i < edge_start[e + 1]; ++i) hexes.push_back(erec[i].slot / 12);
      bad_edge_link.first = std::string(edge_on_boundary[e] ? "boundary" : "interior") + " edge (" +
                            std::to_string(erec[edge_start[e]].lo) + ", " +
                            std::to_string(erec[edge_start[e]].hi) + ") in hexes " +
                            id_list(hexes.begin(), hexes.end());
    }
  }

  // Vertex links. Incidences (8*hex + corner) grouped by point in one counting pass.
  std::vector<int32_t> inc_start(np + 1, 0), inc(8 * static_cast<size_t>(nh));
  for (const Hex& hx : mesh.hexes)
    for (int32_t v : hx) ++inc_start[v + 1];
  for (int32_t v = 0; v < np; ++v) inc_start[v + 1] += inc_start[v];
  {
    std::vector<int32_t> fill(inc_start.begin(), inc_start.end() - 1);
    for (int32_t h = 0; h < nh; ++h)
      for (int c = 0; c < 8; ++c) inc[fill[mesh.hexes[h][c]]++] = 8 * h + c;
  }
  std::vector<std::array<int32_t, 3>> tris, tri_edges;
  std::vector<LinkEdge> ledges;
  std::vector<int32_t> ledge_start, lverts;
  UnionFind uf_half, uf_vert;
  for (int32_t v = 0; v < np; ++v) {
    if (!used[v]) continue;
    tris.clear();
    ledges.clear();
    lverts.clear();
    for (int32_t i = inc_start[v]; i < inc_start[v + 1]; ++i) {
      const int32_t h = inc[i] / 8, c = inc[i] % 8;
      const auto& fr = kHexCornerFrames[c];
      const std::array<int32_t, 3> n{mesh.hexes[h][fr[0]], mesh.hexes[h][fr[1]], mesh.hexes[h][fr[2]]};
      const auto tri = static_cast<int32_t>(tris.size());
      tris.push_back(n);
      for (int j = 0; j < 3; ++j) {
        ledges.push_back({std::min(n[j], n[(j + 1) % 3]), std::max(n[j], n[(j + 1) % 3]), tri});
        lverts.push_back(n[j]);
      }
    }
    std::sort(lverts.begin(), lverts.end());
    lverts.erase(std::unique(lverts.begin(), lverts.end()), lverts.end());
    ledge_start.clear();
    std::sort(ledges.begin(), ledges.end(), [](const LinkEdge& a, const LinkEdge& b) {
      return std::tie(a.lo, a.hi, a.tri) < std::tie(b.lo, b.hi, b.tri);
    });
    for (size_t i = 0; i < ledges.size(); ++i)
      if (i == 0 || ledges[i].lo != ledges[i - 1].lo || ledges[i].hi != ledges[i - 1].hi)
        ledge_start.push_back(static_cast<int32_t>(i));
    const auto n_edges = static_cast<int32_t>(ledge_start.size());
    ledge_start.push_back(static_cast<int32_t>(ledges.size()));

    bool ok = true;
    int32_t open_edges = 0;
    for (int32_t le = 0; le < n_edges; ++le) {
      const int32_t uses = ledge_start[le + 1] - ledge_start[le];
      ok = ok && ledges[ledge_start[le]].lo != ledges[ledge_start[le]].hi && uses <= 2;
      open_edges += uses == 1;
    }
    const bool boundary = vertex_on_boundary[v] != 0;
    ok = ok && (boundary ? open_edges > 0 : open_edges == 0);
    const int64_t chi = static_cast<int64_t>(lverts.size()) - n_edges + static_cast<int64_t>(tris.size());
    ok = ok && chi == (boundary ? 1 : 2);

    // Index of link edge (a, b) in the unique list.
    auto edge_index = [&](int32_t a, int32_t b) {
      const LinkEdge key{std::min(a, b), std::max(a, b), -1};
      const auto it = std::lower_bound(ledge_start.begin(), ledge_start.begin() + n_edges, key,
                                       [&](int32_t pos, const LinkEdge& k) {
                                         return std::tie(ledges[pos].lo, ledges[pos].hi) <
                                                std::tie(k.lo, k.hi);
                                       });
      return static_cast<int32_t>(it - ledge_start.begin());
    };
    auto vert_index = [&](int32_t a) {
      return static_cast<int32_t>(std::lower_bound(lverts.begin(), lverts.end(), a) - lverts.begin());
    };
    // Around every link vertex x, the triangles at x must chain its link edges into one fan
    // (a cycle or a path): union "half edges" (edge, end x) through the triangles at x and
    // expect exactly one class per link vertex. And the link must be connected.
    uf_half.reset(2 * static_cast<size_t>(n_edges));
    uf_vert.reset(lverts.size());
    for (const auto& n : tris)
      for (int j = 0; j < 3; ++j) {
        const int32_t x = n[j], prev = n[(j + 2) % 3], next = n[(j + 1) % 3];
        const int32_t e_prev = edge_index(prev, x), e_next = edge_index(x, next);
        auto half = [&](int32_t e) { return 2 * e + (ledges[ledge_start[e]].hi == x ? 1 : 0); };
        uf_half.unite(half(e_prev), half(e_next));
        uf_vert.unite(vert_index(x), vert_index(next));
      }
    int32_t half_classes = 0, vert_classes = 0;
    for (int32_t i = 0; i < 2 * n_edges; ++i) half_classes += uf_half.find(i) == i;
    for (int32_t i = 0; i < static_cast<int32_t>(lverts.size()); ++i) vert_classes += uf_vert.find(i) == i;
    ok = ok && half_classes == static_cast<int32_t>(lverts.size()) && vert_classes == 1;
    if (!ok && bad_vertex_link.count++ == 0)
      bad_vertex_link.first = std::string(boundary ? "boundary" : "interior") + " point " +
                              std::to_string(v) + " (" + std::to_string(tris.size()) +
                              " hexes, link Euler characteristic " + std::to_string(chi) + ")";
  }

  // Hexes connected through shared faces.
  uf.reset(nh);
  for (int32_t f = 0; f < t.faces; ++f)
    for (int32_t i = face_start[f] + 1; i < face_start[f + 1]; ++i)
      uf.unite(frec[face_start[f]].slot / 6, frec[i].slot / 6);
  int32_t hex_components = 0;
  for (int32_t h = 0; h < nh; ++h) hex_components += uf.find(h) == h;

  // Boundary surface: one component (through shared vertices), Euler characteristic 2.
  uf.reset(np);
  for (const Quad& q : t.boundary_quads)
    for (int i = 1; i < 4; ++i) uf.unite(q[0], q[i]);
  int32_t boundary_components = 0, boundary_vertices = 0;
  for (int32_t v = 0; v < np; ++v) {
    if (!vertex_on_boundary[v]) continue;
    ++boundary_vertices;
    boundary_components += uf.find(v) == v;
  }
  const int64_t boundary_chi =
      static_cast<int64_t>(boundary_vertices) -
      std::count(edge_on_boundary.begin(), edge_on_boundary.end(), 1) + t.boundary_faces;

  std::vector<std::string> problems;
  for (const Finding* f : {&repeated, &overused, &bad_edge_link, &bad_vertex_link})
    if (f->count > 0)
      problems.push_back(std::string(f->what) + ": " + std::to_string(f->count) + " (first: " +
                         f->first + ")");
  if (hex_components != 1)
    problems.push_back("hexes fall into " + std::to_string(hex_components) +
                       " face-connected components");
  if (t.boundary_faces == 0)
    problems.push_back("the complex has no boundary faces");
  else if (boundary_components != 1 || boundary_chi != 2)
    problems.push_back("boundary surface has " + std::to_string(boundary_components) +
                       " component(s) and Euler characteristic " + std::to_string(boundary_chi) +
                       " (a sphere: 1 component, Euler characteristic 2)");
  if (t.euler_characteristic != 1)
    problems.push_back("Euler characteristic V - E + F - C = " + std::to_string(t.vertices) +
                       " - " + std::to_string(t.edges) + " + " + std::to_string(t.faces) + " - " +
                       std::to_string(nh) + " = " + std::to_string(t.euler_characteristic) +
                       " (a ball has 1)");
  t.is_ball = problems.empty();
  for (size_t i = 0; i < problems.size(); ++i) t.message += (i ? "; " : "") + problems[i];
  return t;
}

}  // namespace hexpeel::quality_detail
