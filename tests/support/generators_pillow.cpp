// Random pillowing of a known hex mesh: harder surfaces whose hex count of one valid answer is
// known.
//
// Pillowing (Mitchell & Tautges 1995, "Pillowing doublets: refining a mesh to ensure that faces
// share at most one edge"): for a shrink set S of hexes, every vertex of a face shared by a hex in
// S and a hex outside S (the interface) is duplicated; hexes of S take the duplicates and one new
// hex is inserted between each interface face and its duplicate. Faces of S on the mesh boundary
// get no hex: where the interface reaches the boundary, the side faces of the new hexes become
// boundary quads, i.e. the surface gains a ring of quads (the sheet's trace) and its boundary
// vertices are split. The result's surface is the new mesh's boundary.
//
// S grows from a random hex by random face neighbours; a growth step is kept only when the
// pillowed mesh passes check_hex_complex (a 3-ball complex with a sphere boundary) and has no
// more non-positive hexes than the input, so the output is valid by construction. Duplicates are
// placed 35% of the way towards the centroid of their S-side neighbourhood (on the boundary: the
// centroid of the incident boundary faces of S, which keeps them on flat boundary patches).
// Consequences: the count of non-positive hexes never grows, and S is smaller than asked when
// growth keeps failing (it stops after a budget of attempts).
#include "support/generators_internal.h"

#include <algorithm>
#include <cmath>

namespace hexpeel::testing {
namespace {

/// How far a duplicate moves towards its S-side centroid (fraction of the distance, 0..1).
constexpr double kShrink = 0.35;

/// The mesh's facet adjacency: across[6*h+lf] = the hex on the other side, -1 on the boundary.
std::vector<int32_t> facet_neighbours(const HexMesh& mesh) {
  struct Item {
    Quad key;
    int32_t facet;
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
    for (int i = 0; i < 4; ++i)
      if (a.key[i] != b.key[i]) return a.key[i] < b.key[i];
    return a.facet < b.facet;
  });
  std::vector<int32_t> across(items.size(), -1);
  for (size_t i = 0; i + 1 < items.size(); ++i)
    if (items[i].key == items[i + 1].key) {
      across[items[i].facet] = items[i + 1].facet / 6;
      across[items[i + 1].facet] = items[i].facet / 6;
    }
  return across;
}

/// The mesh pillowed around the hexes with in_s[h] != 0 (see the file comment). `changed` (if
/// given) receives the duplicated vertices and their duplicates: the only vertices whose links
/// differ from the input's (any other vertex has only S hexes or only non-S hexes around it).
HexMesh pillow(const HexMesh& mesh, const std::vector<int32_t>& across,
               const std::vector<uint8_t>& in_s, std::vector<int32_t>* changed = nullptr) {
  const int32_t np = mesh.num_points(), nh = mesh.num_hexes();
  std::vector<int32_t> dup(np, -1), interface;
  int32_t added = 0;
  for (int32_t h = 0; h < nh; ++h) {
    if (!in_s[h]) continue;
    for (int lf = 0; lf < 6; ++lf) {
      const int32_t o = across[6 * h + lf];
      if (o < 0 || in_s[o]) continue;
      interface.push_back(6 * h + lf);
      for (int i = 0; i < 4; ++i) {
        const int32_t v = mesh.hexes[h][kHexFaces[lf][i]];
        if (dup[v] < 0) dup[v] = np + added++;
      }
    }
  }
  if (changed) {
    changed->clear();
    for (int32_t v = 0; v < np; ++v)
      if (dup[v] >= 0) {
        changed->push_back(v);
        changed->push_back(dup[v]);
      }
  }
  HexMesh out;
  out.points = mesh.points;
  out.points.resize(np + added);
  // Targets: boundary faces of S for boundary vertices, else the centres of S's hexes.
  std::vector<Vec3> face_sum(added, Vec3::Zero()), hex_sum(added, Vec3::Zero());
  std::vector<int32_t> face_count(added, 0), hex_count(added, 0);
  for (int32_t h = 0; h < nh; ++h) {
    if (!in_s[h]) continue;
    const Hex& hex = mesh.hexes[h];
    Vec3 centre = Vec3::Zero();
    for (int32_t v : hex) centre += mesh.points[v] / 8.0;
    for (int32_t v : hex)
      if (dup[v] >= 0) {
        hex_sum[dup[v] - np] += centre;
        ++hex_count[dup[v] - np];
      }
    for (int lf = 0; lf < 6; ++lf) {
      if (across[6 * h + lf] >= 0) continue;
      Vec3 c = Vec3::Zero();
      for (int i = 0; i < 4; ++i) c += mesh.points[hex[kHexFaces[lf][i]]] / 4.0;
      for (int i = 0; i < 4; ++i)
        if (const int32_t d = dup[hex[kHexFaces[lf][i]]]; d >= 0) {
          face_sum[d - np] += c;
          ++face_count[d - np];
        }
    }
  }
  for (int32_t v = 0; v < np; ++v) {
    if (dup[v] < 0) continue;
    const int32_t i = dup[v] - np;
    const Vec3 target = face_count[i] > 0 ? Vec3(face_sum[i] / face_count[i])
                                          : Vec3(hex_sum[i] / std::max(hex_count[i], 1));
    out.points[dup[v]] = mesh.points[v] + kShrink * (target - mesh.points[v]);
  }
  out.hexes = mesh.hexes;
  for (int32_t h = 0; h < nh; ++h)
    if (in_s[h])
      for (int32_t& v : out.hexes[h])
        if (dup[v] >= 0) v = dup[v];
  // The interface face a,b,c,d is oriented out of S: its duplicate is the new hex's bottom, whose
  // right-hand normal then points to the top a,b,c,d as VTK requires.
  for (int32_t facet : interface) {
    const Hex& hex = mesh.hexes[facet / 6];
    const auto& lf = kHexFaces[facet % 6];
    Hex nh8;
    for (int i = 0; i < 4; ++i) {
      nh8[i] = dup[hex[lf[i]]];
      nh8[i + 4] = hex[lf[i]];
    }
    out.hexes.push_back(nh8);
  }
  return out;
}

}  // namespace

Generated pillowed(const Generated& g, uint64_t seed, double fraction) {
  const HexMesh& mesh = g.known_mesh;
  const int32_t nh = mesh.num_hexes();
  if (nh < 2) {
    Generated out = g;
    out.name = g.name + "_pillow_s" + std::to_string(seed);
    return out;
  }
  const std::vector<int32_t> across = facet_neighbours(mesh);
  const int32_t target = std::clamp(static_cast<int32_t>(std::lround(fraction * nh)), 1, nh - 1);
  detail::Rng rng(seed);
  std::vector<uint8_t> in_s(nh, 0), rejected(nh, 0);
  // A shrink set is kept when the pillowed mesh is a valid complex with no more non-positive
  // hexes than the input (the centroid placement cannot serve every shape of S, e.g. S hexes
  // meeting diagonally at a vertex).
  const int32_t non_positive = nh - count_positive_hexes(mesh);
  std::vector<int32_t> changed;
  auto valid = [&]() {
    const HexMesh p = pillow(mesh, across, in_s, &changed);
    return p.num_hexes() - count_positive_hexes(p) <= non_positive &&
           detail::check_hex_complex(p, &changed).empty();
  };

  // A start hex whose pillow is valid (almost always the first one tried).
  int32_t count = 0;
  for (int attempt = 0; attempt < nh && count == 0; ++attempt) {
    const int32_t h = static_cast<int32_t>(rng.below(nh));
    in_s[h] = 1;
    if (valid())
      count = 1;
    else
      in_s[h] = 0;
  }
  // Grow by random face neighbours; a failed candidate is retried only after a success.
  int64_t budget = 10 * static_cast<int64_t>(target) + 100;
  std::vector<int32_t> candidates;
  while (count > 0 && count < target && budget-- > 0) {
    candidates.clear();
    for (int32_t h = 0; h < nh; ++h) {
      if (!in_s[h]) continue;
      for (int lf = 0; lf < 6; ++lf)
        if (const int32_t o = across[6 * h + lf]; o >= 0 && !in_s[o] && !rejected[o])
          candidates.push_back(o);
    }
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    if (candidates.empty()) break;
    const int32_t h = candidates[rng.below(candidates.size())];
    in_s[h] = 1;
    if (valid()) {
      ++count;
      std::fill(rejected.begin(), rejected.end(), 0);
    } else {
      in_s[h] = 0;
      rejected[h] = 1;
    }
  }
  if (count == 0) {
    Generated out = g;
    out.name = g.name + "_pillow_s" + std::to_string(seed);
    return out;
  }
  return detail::from_hex_mesh(g.name + "_pillow_s" + std::to_string(seed),
                               pillow(mesh, across, in_s));
}

}  // namespace hexpeel::testing
