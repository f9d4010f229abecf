// Input checking (DESIGN.md "Input checking"): turns a PolygonSoup into a closed, manifold,
// consistently and outward oriented, genus-0, single-component all-quad QuadSurface, or says
// precisely why it cannot, naming the offending face and vertex ids (input numbering).
//
// The checks run in three stages, each needing the previous one to pass:
//   1. per element: index range, finite coordinates, four corners, non-degenerate quads,
//      duplicate vertex positions. Every class found is reported; any of them stops here,
//      because the topology of such a soup is meaningless (an unwelded duplicate vertex would
//      show up again as an open boundary).
//   2. topology, on the quads with unused vertices dropped: non-manifold edges, open boundary
//      edges, non-manifold vertices (several fans of quads around one vertex), inconsistent
//      orientation (the smaller class of an orientable surface is reversed and warned, or
//      rejected), several edge-connected components; then, on a closed manifold oriented
//      surface, the genus of each component (Euler characteristic) and the parity of the quad
//      count (the boundary of a hex mesh has 6H - 2I quads, an even number).
//   3. orientation: a surface that encloses a negative volume is flipped (warned) or rejected.
//   4. geometry: quads that cut through or touch each other away from their shared vertices and
//      edges (intersection.h) are refused in pairs.
// Never crashes, whatever the soup: the checks read only what the earlier ones proved valid.
#include "hexpeel/validation.h"

#include "hexpeel/intersection.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>
#include <tuple>
#include <utility>

namespace hexpeel {
namespace {

/// How many items a message lists before "and N more".
constexpr size_t kListedInMessage = 10;
/// How many ids an issue keeps in its faces / vertices vectors.
constexpr size_t kKeptIds = 100;

/// Collects the items of one message, keeping the first few and counting the rest.
struct Listing {
  std::vector<std::string> shown;  ///< first kListedInMessage items, in discovery order
  int64_t total = 0;               ///< items added so far

  void add(std::string item) {
    if (shown.size() < kListedInMessage) shown.push_back(std::move(item));
    ++total;
  }
  bool empty() const { return total == 0; }
  std::string text() const {
    std::string s;
    for (size_t i = 0; i < shown.size(); ++i) {
      if (i) s += ", ";
      s += shown[i];
    }
    if (total > static_cast<int64_t>(shown.size()))
      s += " and " + std::to_string(total - static_cast<int64_t>(shown.size())) + " more";
    return s;
  }
};

void keep_id(std::vector<int32_t>& ids, int32_t id) {
  if (ids.size() < kKeptIds && std::find(ids.begin(), ids.end(), id) == ids.end())
    ids.push_back(id);
}

std::string fmt_point(const Vec3& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.9g, %.9g, %.9g)", p.x(), p.y(), p.z());
  return buf;
}

std::string plural(int64_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

/// Union-find over dense ids with path halving; the representative is arbitrary.
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

/// The state of one validation run: the result being filled and what later checks need.
struct Validator {
  const PolygonSoup& soup;
  const ValidationParams& params;
  const Context& ctx;
  ValidationResult result;
  double diagonal = 0.0;          ///< bbox diagonal of the used, finite vertices

  void issue(StatusCode code, std::string message, std::vector<int32_t> faces = {},
             std::vector<int32_t> vertices = {}) {
    result.issues.push_back({code, std::move(message), std::move(faces), std::move(vertices)});
  }
  void warn(std::string message) {
    ctx.warn(message);
    result.warnings.push_back(std::move(message));
  }

  int32_t num_faces() const {
    return soup.offsets.empty() ? 0 : static_cast<int32_t>(soup.offsets.size()) - 1;
  }
  int32_t num_points() const { return static_cast<int32_t>(soup.points.size()); }

  bool check_offsets();
  void check_elements();
  void check_duplicates(const std::vector<uint8_t>& used);
  void build_surface();
  void check_topology();
  void check_orientation();
  void check_self_intersection();
};

/// Readers guarantee well-formed offsets; a hand-built soup may not. Stop on the first bad one.
bool Validator::check_offsets() {
  const auto& off = soup.offsets;
  if (off.empty()) return true;
  const int64_t n_indices = static_cast<int64_t>(soup.indices.size());
  if (off.front() != 0) {
    issue(StatusCode::index_out_of_range,
          "face offsets must start at 0, they start at " + std::to_string(off.front()));
    return false;
  }
  for (int32_t f = 0; f + 1 < static_cast<int32_t>(off.size()); ++f) {
    if (off[f + 1] < off[f] || off[f + 1] > n_indices) {
      issue(StatusCode::index_out_of_range,
            "face " + std::to_string(f) + " has malformed corner offsets " +
                std::to_string(off[f]) + ".." + std::to_string(off[f + 1]) + " (" +
                std::to_string(n_indices) + " corner indices in all)",
            {f});
      return false;
    }
  }
  return true;
}

/// Stage 1: index range, finite coordinates, four corners, degenerate quads, duplicates.
void Validator::check_elements() {
  const int32_t nf = num_faces(), nv = num_points();
  const auto& off = soup.offsets;
  const auto& idx = soup.indices;

  // Which faces have every corner in range, and which vertices they use.
  std::vector<uint8_t> face_in_range(nf, 1), used(nv, 0);
  {
    ValidationIssue out{StatusCode::index_out_of_range, {}, {}, {}};
    Listing items;
    for (int32_t f = 0; f < nf; ++f)
      for (int32_t i = off[f]; i < off[f + 1]; ++i) {
        if (idx[i] < 0 || idx[i] >= nv) {
          if (face_in_range[f]) {
            items.add("face " + std::to_string(f) + " uses vertex " + std::to_string(idx[i]));
            keep_id(out.faces, f);
          }
          face_in_range[f] = 0;
        } else {
          used[idx[i]] = 1;
        }
      }
    if (!items.empty())
      issue(out.code,
            plural(items.total, "face refers", "faces refer") +
                " to vertices that do not exist (" +
                (nv == 0 ? std::string("there are no vertices")
                         : "vertex ids run 0.." + std::to_string(nv - 1)) +
                "): " + items.text(),
            std::move(out.faces));
  }
  {
    std::vector<int32_t> bad;
    Listing items;
    for (int32_t v = 0; v < nv; ++v)
      if (!soup.points[v].allFinite()) {
        items.add(std::to_string(v) + " at " + fmt_point(soup.points[v]));
        keep_id(bad, v);
      }
    if (!items.empty())
      issue(StatusCode::non_finite_coordinate,
            plural(items.total, "vertex has", "vertices have") +
                " a NaN or infinite coordinate: " + items.text(),
            {}, std::move(bad));
  }
  {
    std::vector<int32_t> bad;
    Listing items;
    for (int32_t f = 0; f < nf; ++f)
      if (soup.face_size(f) != 4) {
        items.add("face " + std::to_string(f) + " has " + std::to_string(soup.face_size(f)) +
                  " corners");
        keep_id(bad, f);
      }
    if (!items.empty())
      issue(StatusCode::non_quad_face,
            plural(items.total, "face is not a quad", "faces are not quads") +
                " (hexpeel needs 4 corners per face): " + items.text(),
            std::move(bad));
  }

  // Bounding box of the used finite vertices: the scale for the relative tolerances.
  Eigen::AlignedBox3d box;
  for (int32_t v = 0; v < nv; ++v)
    if (used[v] && soup.points[v].allFinite()) box.extend(soup.points[v]);
  diagonal = box.isEmpty() ? 0.0 : box.diagonal().norm();

  {
    std::vector<int32_t> bad;
    Listing items;
    const double min_area = params.degenerate_area * diagonal * diagonal;
    for (int32_t f = 0; f < nf; ++f) {
      if (soup.face_size(f) != 4 || !face_in_range[f]) continue;
      const int32_t* c = &idx[off[f]];
      int32_t repeated = -1;
      for (int i = 0; i < 4 && repeated < 0; ++i)
        for (int j = i + 1; j < 4; ++j)
          if (c[i] == c[j]) repeated = c[i];
      if (repeated >= 0) {
        items.add("quad " + std::to_string(f) + " repeats vertex " + std::to_string(repeated));
        keep_id(bad, f);
        continue;
      }
      const auto& p = soup.points;
      if (!(p[c[0]].allFinite() && p[c[1]].allFinite() && p[c[2]].allFinite() &&
            p[c[3]].allFinite()))
        continue;
      const double area = 0.5 * (p[c[2]] - p[c[0]]).cross(p[c[3]] - p[c[1]]).norm();
      if (!(area > min_area)) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.3g", area);
        items.add("quad " + std::to_string(f) + " has area " + buf);
        keep_id(bad, f);
      }
    }
    if (!items.empty())
      issue(StatusCode::degenerate_quad,
            plural(items.total, "quad is", "quads are") + " degenerate: " + items.text(),
            std::move(bad));
  }
  check_duplicates(used);
}

/// Two used vertices at the same position (within the tolerance): an unwelded mesh. Sorting,
/// not all pairs: exact duplicates are neighbours in lexicographic order; with a tolerance, the
/// vertices are sorted by a grid cell of the tolerance's size and each is compared with the
/// vertices of the 27 cells around it, found by binary search.
void Validator::check_duplicates(const std::vector<uint8_t>& used) {
  std::vector<int32_t> order;
  for (int32_t v = 0; v < num_points(); ++v)
    if (used[v] && soup.points[v].allFinite()) order.push_back(v);
  if (order.empty()) return;
  const auto& p = soup.points;
  std::vector<int32_t> bad;
  Listing items;
  // Below ~1e-15 of the diagonal a tolerance is lost in rounding anyway: compare exactly.
  const double tol = params.duplicate_tolerance > 1e-15 ? params.duplicate_tolerance * diagonal : 0.0;
  if (tol <= 0.0) {
    std::sort(order.begin(), order.end(), [&](int32_t a, int32_t b) {
      return std::make_tuple(p[a].x(), p[a].y(), p[a].z(), a) <
             std::make_tuple(p[b].x(), p[b].y(), p[b].z(), b);
    });
    for (size_t i = 0; i < order.size();) {
      size_t j = i + 1;
      while (j < order.size() && p[order[j]] == p[order[i]]) ++j;
      if (j - i > 1) {
        std::string group = "vertices";
        for (size_t k = i; k < j && k < i + kListedInMessage; ++k)
          group += (k == i ? " " : (k + 1 == j ? " and " : ", ")) + std::to_string(order[k]);
        if (j - i > kListedInMessage) group += " (" + std::to_string(j - i) + " in all)";
        items.add(group + " at " + fmt_point(p[order[i]]));
        for (size_t k = i; k < j; ++k) keep_id(bad, order[k]);
      }
      i = j;
    }
  } else {
    Vec3 lo = p[order[0]];
    for (int32_t v : order) lo = lo.cwiseMin(p[v]);
    using Cell = std::array<int64_t, 3>;
    auto cell_of = [&](int32_t v) {
      const Vec3 c = (p[v] - lo) / tol;
      return Cell{static_cast<int64_t>(c.x()), static_cast<int64_t>(c.y()),
                  static_cast<int64_t>(c.z())};
    };
    std::vector<std::pair<Cell, int32_t>> cells;
    cells.reserve(order.size());
    for (int32_t v : order) cells.push_back({cell_of(v), v});
    std::sort(cells.begin(), cells.end());
    for (const auto& [cell, v] : cells)
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            const Cell key{cell[0] + dx, cell[1] + dy, cell[2] + dz};
            auto it = std::lower_bound(cells.begin(), cells.end(), std::make_pair(key, v + 1));
            for (; it != cells.end() && it->first == key; ++it) {
              const int32_t w = it->second;  // each pair once: w > v
              if ((p[w] - p[v]).norm() > tol) continue;
              items.add("vertices " + std::to_string(v) + " and " + std::to_string(w) + " near " +
                        fmt_point(p[v]));
              keep_id(bad, v);
              keep_id(bad, w);
            }
          }
  }
  if (!items.empty())
    issue(StatusCode::duplicate_vertex,
          plural(items.total, tol > 0.0 ? "pair" : "group", tol > 0.0 ? "pairs" : "groups") +
              " of distinct vertices share a position (the mesh is not welded): " + items.text(),
          {}, std::move(bad));
}

/// Copies the quads (all valid after stage 1) and drops unused vertices, keeping the map back.
void Validator::build_surface() {
  const int32_t nf = num_faces(), nv = num_points();
  std::vector<int32_t> new_id(nv, -1);
  for (int32_t f = 0; f < nf; ++f)
    for (int i = 0; i < 4; ++i) new_id[soup.indices[soup.offsets[f] + i]] = 0;
  QuadSurface& s = result.surface;
  Listing unused;
  for (int32_t v = 0; v < nv; ++v) {
    if (new_id[v] < 0) {
      unused.add(std::to_string(v));
      continue;
    }
    new_id[v] = static_cast<int32_t>(s.points.size());
    s.points.push_back(soup.points[v]);
    result.input_vertex.push_back(v);
  }
  s.quads.resize(nf);
  for (int32_t f = 0; f < nf; ++f)
    for (int i = 0; i < 4; ++i) s.quads[f][i] = new_id[soup.indices[soup.offsets[f] + i]];
  result.stats.unused_vertices = static_cast<int32_t>(unused.total);
  if (!unused.empty())
    warn(plural(unused.total, "vertex is", "vertices are") +
         " used by no face and dropped: " + unused.text());
}

/// Stage 2: edges, fans, orientation, components, genus, parity.
void Validator::check_topology() {
  const QuadSurface& s = result.surface;
  const auto& in = result.input_vertex;
  const int32_t nq = s.num_quads();
  auto vid = [&](int32_t v) { return std::to_string(in[v]); };

  // Half-edges sorted by undirected key; each run of equal keys is one edge.
  struct Item { int32_t lo, hi, he; };
  std::vector<Item> items;
  items.reserve(4 * static_cast<size_t>(nq));
  for (int32_t q = 0; q < nq; ++q)
    for (int k = 0; k < 4; ++k) {
      int32_t a = s.quads[q][k], b = s.quads[q][(k + 1) & 3];
      items.push_back({std::min(a, b), std::max(a, b), 4 * q + k});
    }
  std::sort(items.begin(), items.end(), [](const Item& x, const Item& y) {
    return std::tie(x.lo, x.hi, x.he) < std::tie(y.lo, y.hi, y.he);
  });
  auto from = [&](int32_t he) { return s.quads[he >> 2][he & 3]; };

  std::vector<int32_t> opposite(items.size(), -1);  // manifold edges only
  std::vector<uint8_t> on_nonmanifold_edge(result.surface.num_points(), 0);
  std::vector<uint8_t> flipped_pair(items.size(), 0);  // opposite traverses the edge the same way
  UnionFind quads_uf(nq);
  ValidationIssue open{StatusCode::open_boundary, {}, {}, {}},
      nonmanifold{StatusCode::non_manifold_edge, {}, {}, {}},
      orient{StatusCode::inconsistent_orientation, {}, {}, {}};
  Listing open_items, nm_items, orient_items;
  int32_t edges = 0;
  for (size_t i = 0; i < items.size();) {
    size_t j = i;
    while (j < items.size() && items[j].lo == items[i].lo && items[j].hi == items[i].hi) ++j;
    ++edges;
    const std::string edge = "(" + vid(items[i].lo) + "," + vid(items[i].hi) + ")";
    for (size_t k = i + 1; k < j; ++k) quads_uf.unite(items[i].he >> 2, items[k].he >> 2);
    if (j - i == 1) {
      const int32_t q = items[i].he >> 2;
      open_items.add("edge " + edge + " of quad " + std::to_string(q));
      keep_id(open.faces, q);
      keep_id(open.vertices, in[items[i].lo]);
      keep_id(open.vertices, in[items[i].hi]);
    } else if (j - i > 2) {
      std::string quads;
      for (size_t k = i; k < j; ++k) {
        quads += (k == i ? "" : (k + 1 == j ? " and " : ", ")) + std::to_string(items[k].he >> 2);
        keep_id(nonmanifold.faces, items[k].he >> 2);
      }
      nm_items.add("edge " + edge + " is shared by quads " + quads);
      on_nonmanifold_edge[items[i].lo] = on_nonmanifold_edge[items[i].hi] = 1;
      keep_id(nonmanifold.vertices, in[items[i].lo]);
      keep_id(nonmanifold.vertices, in[items[i].hi]);
    } else {
      const int32_t h0 = items[i].he, h1 = items[i + 1].he;
      opposite[h0] = h1;
      opposite[h1] = h0;
      if (from(h0) == from(h1)) {
        flipped_pair[h0] = flipped_pair[h1] = 1;
        const int32_t a = from(h0), b = s.quads[h0 >> 2][((h0 & 3) + 1) & 3];
        orient_items.add("quads " + std::to_string(h0 >> 2) + " and " + std::to_string(h1 >> 2) +
                         " both run " + vid(a) + "->" + vid(b));
        keep_id(orient.faces, h0 >> 2);
        keep_id(orient.faces, h1 >> 2);
      }
    }
    i = j;
  }
  result.stats.edges = edges;

  // Fans: corners 4q+k around one vertex joined across the manifold edges at that vertex.
  // More than one class of corners at a vertex = its quads form several fans. The ends of a
  // non-manifold edge always look like that and are reported with their edge already.
  UnionFind corners_uf(4 * static_cast<size_t>(nq));
  for (int32_t he = 0; he < 4 * nq; ++he) {
    const int32_t o = opposite[he];
    if (o < he) continue;
    const int32_t q = he >> 2, k = he & 3, p = o >> 2, m = o & 3;
    // Corners of he's quad at its two ends, and the corner of o's quad at the same vertex.
    for (int end = 0; end < 2; ++end) {
      const int32_t c = 4 * q + ((k + end) & 3);
      const int32_t v = s.quads[q][(k + end) & 3];
      const int32_t d = s.quads[p][m] == v ? 4 * p + m : 4 * p + ((m + 1) & 3);
      corners_uf.unite(c, d);
    }
  }
  std::vector<int32_t> fan_vertices;
  Listing fans;
  {
    std::vector<std::pair<int32_t, int32_t>> vertex_fan;  // (vertex, corner class)
    vertex_fan.reserve(4 * static_cast<size_t>(nq));
    for (int32_t c = 0; c < 4 * nq; ++c) vertex_fan.push_back({s.quads[c >> 2][c & 3], corners_uf.find(c)});
    std::sort(vertex_fan.begin(), vertex_fan.end());
    vertex_fan.erase(std::unique(vertex_fan.begin(), vertex_fan.end()), vertex_fan.end());
    for (size_t i = 0; i < vertex_fan.size();) {
      size_t j = i;
      while (j < vertex_fan.size() && vertex_fan[j].first == vertex_fan[i].first) ++j;
      if (j - i > 1 && !on_nonmanifold_edge[vertex_fan[i].first]) {
        fans.add("vertex " + vid(vertex_fan[i].first) + " (" + std::to_string(j - i) + " fans)");
        keep_id(fan_vertices, in[vertex_fan[i].first]);
      }
      i = j;
    }
  }

  // Components (edge-connected), numbered by their smallest quad.
  std::vector<int32_t> component(nq, -1), first_quad;
  for (int32_t q = 0; q < nq; ++q) {
    const int32_t r = quads_uf.find(q);
    if (component[r] < 0) {
      component[r] = static_cast<int32_t>(first_quad.size());
      first_quad.push_back(q);
    }
    component[q] = component[r];
  }
  const int32_t nc = static_cast<int32_t>(first_quad.size());
  result.stats.components = nc;

  if (!nm_items.empty())
    issue(nonmanifold.code,
          plural(nm_items.total, "edge is", "edges are") +
              " shared by more than two quads: " + nm_items.text(),
          std::move(nonmanifold.faces), std::move(nonmanifold.vertices));
  if (!open_items.empty())
    issue(open.code,
          plural(open_items.total, "edge is", "edges are") +
              " used by one quad only (the surface is not closed): " + open_items.text(),
          std::move(open.faces), std::move(open.vertices));
  if (!fans.empty())
    issue(StatusCode::non_manifold_vertex,
          plural(fans.total, "vertex is", "vertices are") +
              " non-manifold, the quads around each forming several separate fans: " +
              fans.text(),
          {}, std::move(fan_vertices));

  if (!orient_items.empty()) {
    // Which quads to reverse: 2-colour each component across manifold edges (a same-direction
    // edge changes the colour); the smaller colour class is the likely culprit.
    std::vector<int8_t> colour(nq, -1);
    std::vector<int32_t> stack, minority;
    bool orientable = true;
    for (int32_t start = 0; start < nq; ++start) {
      if (colour[start] >= 0) continue;
      std::vector<int32_t> members[2];
      colour[start] = 0;
      stack.push_back(start);
      while (!stack.empty()) {
        const int32_t q = stack.back();
        stack.pop_back();
        members[colour[q]].push_back(q);
        for (int k = 0; k < 4; ++k) {
          const int32_t o = opposite[4 * q + k];
          if (o < 0) continue;
          const int8_t want = static_cast<int8_t>(colour[q] ^ flipped_pair[4 * q + k]);
          if (colour[o >> 2] < 0) {
            colour[o >> 2] = want;
            stack.push_back(o >> 2);
          } else if (colour[o >> 2] != want) {
            orientable = false;
          }
        }
      }
      auto& few = members[0].size() <= members[1].size() ? members[0] : members[1];
      minority.insert(minority.end(), few.begin(), few.end());
    }
    // Only a surface that is otherwise a closed manifold is re-oriented; then it is checked
    // again from the start, as if it had been given that way.
    std::sort(minority.begin(), minority.end());
    if (orientable && params.reorient && result.issues.empty()) {
      Listing rev;
      for (int32_t q : minority) {
        std::swap(result.surface.quads[q][1], result.surface.quads[q][3]);
        rev.add(std::to_string(q));
      }
      result.stats.reoriented = minority;
      warn("the quads' orientations disagree across " +
           plural(orient_items.total, "edge", "edges") + "; " +
           plural(rev.total, "quad was", "quads were") + " reversed to agree with the rest: " +
           rev.text());
      check_topology();
      return;
    }
    std::string hint;
    if (!orientable) {
      hint = "; the surface is not orientable";
    } else {
      Listing rev;
      for (int32_t q : minority) rev.add(std::to_string(q));
      hint = std::string("; reversing quad") + (rev.total == 1 ? " " : "s ") + rev.text() +
             " would make it consistent";
    }
    issue(orient.code,
          plural(orient_items.total, "edge is", "edges are") +
              " traversed in the same direction by both their quads: " + orient_items.text() + hint,
          std::move(orient.faces));
  }

  if (nc > 1) {
    Listing comps;
    for (int32_t c = 0; c < nc; ++c) comps.add(std::to_string(first_quad[c]));
    issue(StatusCode::multiple_components,
          "the surface has " + std::to_string(nc) +
              " separate parts (one quad of each: " + comps.text() +
              "); hexpeel meshes one closed surface at a time",
          std::vector<int32_t>(first_quad.begin(),
                               first_quad.begin() + std::min<size_t>(first_quad.size(), kKeptIds)));
  }

  // Genus and parity only mean something on a closed, manifold, oriented surface.
  if (!open_items.empty() || !nm_items.empty() || !orient_items.empty() || !fans.empty()) return;

  std::vector<int64_t> chi(nc, 0);  // V - E + F per component
  for (int32_t q = 0; q < nq; ++q) chi[component[q]] += 1;
  for (int32_t he = 0; he < 4 * nq; ++he)
    if (opposite[he] > he) chi[component[he >> 2]] -= 1;
  {
    std::vector<int32_t> vertex_comp(s.num_points(), -1);
    for (int32_t q = 0; q < nq; ++q)
      for (int32_t v : s.quads[q])
        if (vertex_comp[v] < 0) {
          vertex_comp[v] = component[q];
          chi[component[q]] += 1;
        }
  }
  int32_t genus_sum = 0;
  Listing handles;
  std::vector<int32_t> handle_quads;
  for (int32_t c = 0; c < nc; ++c) {
    const int64_t g = (2 - chi[c]) / 2;
    genus_sum += static_cast<int32_t>(g);
    if (g == 0) continue;
    if (nc == 1)
      handles.add("the surface has genus " + std::to_string(g) + " (V - E + F = " +
                  std::to_string(chi[c]) + ", a sphere has 2)");
    else
      handles.add("part " + std::to_string(c) + " (quad " + std::to_string(first_quad[c]) +
                  ") has genus " + std::to_string(g) + " (V - E + F = " + std::to_string(chi[c]) +
                  ")");
    keep_id(handle_quads, first_quad[c]);
  }
  result.stats.genus = genus_sum;
  if (!handles.empty())
    issue(StatusCode::nonzero_genus,
          handles.text() + "; hexpeel needs a topological sphere (genus 0), a surface with "
                           "handles or tunnels cannot be meshed by dual cycle elimination",
          std::move(handle_quads));

  if (nq % 2 != 0 && !params.allow_odd)
    issue(StatusCode::odd_quad_count,
          std::to_string(nq) +
              " quads: the boundary of any hex mesh has an even number of quads, so no hex "
              "mesh can exist (`hexpeel mesh --repair-surface` refines it into an even surface)");
}

/// Stage 3: outward orientation (the right-hand normals must point out of the enclosed volume).
void Validator::check_orientation() {
  QuadSurface& s = result.surface;
  const double vol = signed_volume(s);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", vol);
  if (!(std::abs(vol) > 1e-12 * diagonal * diagonal * diagonal)) {
    warn(std::string("the surface encloses no volume (signed volume ") + buf +
         "): its orientation cannot be checked");
    return;
  }
  if (vol > 0) return;
  if (!params.flip_inward) {
    issue(StatusCode::inconsistent_orientation,
          std::string("the surface is oriented inward (signed volume ") + buf +
              "): quads must be counter-clockwise seen from outside");
    return;
  }
  for (Quad& f : s.quads) std::swap(f[1], f[3]);
  result.stats.flipped = true;
  warn(std::string("the surface was oriented inward (signed volume ") + buf +
       "); every quad has been reversed to face outward");
}

/// Stage 4: the quads must not meet except at the vertices and edges they share.
void Validator::check_self_intersection() {
  const SelfIntersections si = find_self_intersections(result.surface, 10);
  if (si.total == 0) return;
  std::string list;
  std::vector<int32_t> faces;
  for (const auto& [a, b] : si.pairs) {
    list += (list.empty() ? "" : ", ") + std::to_string(a) + " and " + std::to_string(b);
    keep_id(faces, a);
    keep_id(faces, b);
  }
  if (si.total > static_cast<int64_t>(si.pairs.size()))
    list += " and " + std::to_string(si.total - static_cast<int64_t>(si.pairs.size())) + " more pairs";
  issue(StatusCode::self_intersecting_surface,
        "the surface intersects itself: " +
            plural(si.total, "pair of quads meets", "pairs of quads meet") +
            " away from their shared vertices and edges (quads " + list +
            "); it bounds no solid, so no hex mesh of it can be valid",
        std::move(faces));
}

}  // namespace

ValidationResult run_validation(const PolygonSoup& soup, const ValidationParams& params,
                                const Context& ctx) {
  Validator val{soup, params, ctx, {}};
  ValidationResult& r = val.result;
  r.stats.points = val.num_points();
  r.stats.faces = val.num_faces();
  auto finish = [&]() -> ValidationResult {
    if (!r.issues.empty()) r.status = Status::error(r.issues.front().code, r.issues.front().message);
    return std::move(r);
  };

  if (!val.check_offsets()) return finish();
  if (val.num_faces() == 0) {
    val.issue(StatusCode::empty_mesh, "the surface has no faces (" +
                                          plural(val.num_points(), "vertex", "vertices") + ")");
    return finish();
  }
  val.check_elements();
  if (!r.issues.empty()) return finish();
  val.build_surface();
  val.check_topology();
  if (!r.issues.empty()) return finish();
  val.check_orientation();
  if (!r.issues.empty() || !params.check_self_intersection) return finish();
  val.check_self_intersection();
  return finish();
}

}  // namespace hexpeel
