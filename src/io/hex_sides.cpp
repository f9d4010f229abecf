// Boundary sides by sorting: each side's vertex set becomes a sorted 4-tuple, the tuples are sorted,
// and a tuple without an equal neighbour is a boundary side. O(H log H), deterministic.
#include "io/hex_sides.h"

#include <algorithm>
#include <string>

namespace hexpeel::io {

namespace {

struct KeyedSide {
  std::array<int32_t, 4> key;  ///< the side's vertices, sorted
  HexSide side;
};

}  // namespace

std::vector<HexSide> boundary_sides(const HexMesh& mesh, const SideTable& table) {
  std::vector<KeyedSide> all;
  all.reserve(mesh.hexes.size() * 6);
  for (int32_t h = 0; h < mesh.num_hexes(); ++h) {
    for (int32_t s = 0; s < 6; ++s) {
      KeyedSide k{{}, {h, s}};
      for (int c = 0; c < 4; ++c) k.key[c] = mesh.hexes[h][table[s][c]];
      std::sort(k.key.begin(), k.key.end());
      all.push_back(k);
    }
  }
  std::sort(all.begin(), all.end(), [](const KeyedSide& a, const KeyedSide& b) { return a.key < b.key; });
  std::vector<HexSide> out;
  for (size_t i = 0; i < all.size();) {
    size_t j = i + 1;
    while (j < all.size() && all[j].key == all[i].key) ++j;
    if (j == i + 1) out.push_back(all[i].side);
    i = j;
  }
  std::sort(out.begin(), out.end(), [](const HexSide& a, const HexSide& b) {
    return a.hex != b.hex ? a.hex < b.hex : a.side < b.side;
  });
  return out;
}

std::vector<int32_t> side_vertices(const HexMesh& mesh, const SideTable& table,
                                   const std::vector<HexSide>& sides) {
  std::vector<int32_t> out;
  out.reserve(sides.size() * 4);
  for (const HexSide& s : sides) {
    for (int c : table[s.side]) out.push_back(mesh.hexes[s.hex][c]);
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

namespace {
std::array<int32_t, 4> sorted_key(std::array<int32_t, 4> k) {
  std::sort(k.begin(), k.end());
  return k;
}
}  // namespace

int32_t PatchLookup::patch_at(const HexMesh& mesh, const SideTable& table, const HexSide& side) const {
  std::array<int32_t, 4> k;
  for (int c = 0; c < 4; ++c) k[c] = mesh.hexes[side.hex][table[side.side][c]];
  const auto it = patch_of.find(sorted_key(k));
  return it == patch_of.end() ? -1 : it->second;
}

std::vector<std::vector<HexSide>> PatchLookup::by_patch(const HexMesh& mesh, const SideTable& table,
                                                        const std::vector<HexSide>& sides) const {
  std::vector<std::vector<HexSide>> out(patches != nullptr ? static_cast<size_t>(patches->count) : 0);
  for (const HexSide& side : sides)
    if (const int32_t p = patch_at(mesh, table, side); p >= 0) out[p].push_back(side);
  return out;
}

Status make_patch_lookup(const HexMesh& mesh, const BoundaryPatches& patches, PatchLookup& out) {
  out = PatchLookup{};
  auto bad = [](const std::string& msg) {
    return Status::error(StatusCode::invalid_mesh, "boundary patches: " + msg);
  };
  if (patches.patch.size() != patches.faces.size())
    return bad(std::to_string(patches.faces.size()) + " faces but " +
               std::to_string(patches.patch.size()) + " patch ids");
  if (patches.count < 0) return bad("negative patch count");
  std::map<std::array<int32_t, 4>, int32_t> boundary;  // sorted corners -> 0 (not yet given)
  for (const HexSide& side : boundary_sides(mesh, kHexFaces)) {
    std::array<int32_t, 4> k;
    for (int c = 0; c < 4; ++c) k[c] = mesh.hexes[side.hex][kHexFaces[side.side][c]];
    boundary.emplace(sorted_key(k), 0);
  }
  for (size_t i = 0; i < patches.faces.size(); ++i) {
    const int32_t p = patches.patch[i];
    if (p < 0 || p >= patches.count)
      return bad("face " + std::to_string(i) + " has patch " + std::to_string(p) + ", not in [0, " +
                 std::to_string(patches.count) + ")");
    const std::array<int32_t, 4> k = sorted_key(patches.faces[i]);
    const auto it = boundary.find(k);
    if (it == boundary.end())
      return bad("face " + std::to_string(i) + " (vertices " + std::to_string(patches.faces[i][0]) +
                 " " + std::to_string(patches.faces[i][1]) + " " + std::to_string(patches.faces[i][2]) +
                 " " + std::to_string(patches.faces[i][3]) + ") is not a boundary face of the mesh");
    if (it->second != 0) return bad("face " + std::to_string(i) + " is given twice");
    it->second = 1;
    out.patch_of.emplace(k, p);
  }
  out.patches = &patches;
  return Status::success();
}

}  // namespace hexpeel::io
