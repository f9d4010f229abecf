// Boundary sides by sorting: each side's vertex set becomes a sorted 4-tuple, the tuples are sorted,
// and a tuple without an equal neighbour is a boundary side. O(H log H), deterministic.
#include "io/hex_sides.h"

#include <algorithm>

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

}  // namespace hexpeel::io
