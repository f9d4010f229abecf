// Shared by the robustness and meshio tests: reads damaged copies of a file with every reader
// that accepts its extension and checks that the outcome is a Status and a well-formed result.
#pragma once

#include "hexpeel/io.h"
#include "io_fixtures.h"

#include <gtest/gtest.h>

#include <random>

namespace hexpeel::test_io {

inline void read_and_check(const std::filesystem::path& path) {
  PolygonSoup soup;
  const Status s = read_surface(path, soup);
  if (s.ok()) {
    ASSERT_FALSE(soup.offsets.empty());
    ASSERT_EQ(soup.offsets.front(), 0);
    ASSERT_EQ(soup.offsets.back(), static_cast<int32_t>(soup.indices.size()));
    for (size_t f = 1; f < soup.offsets.size(); ++f) ASSERT_LE(soup.offsets[f - 1], soup.offsets[f]);
    for (int32_t i : soup.indices) ASSERT_TRUE(i >= 0 && i < static_cast<int32_t>(soup.points.size()));
  } else {
    ASSERT_FALSE(s.message.empty());
  }
  if (!is_hex_mesh_extension(path)) return;
  HexMesh mesh;
  int64_t others = 0;
  const Status h = read_hex_mesh(path, mesh, &others);
  if (h.ok()) {
    ASSERT_GT(mesh.num_hexes(), 0);
    for (const Hex& hex : mesh.hexes) {
      for (int32_t i : hex) ASSERT_TRUE(i >= 0 && i < mesh.num_points());
    }
  } else {
    ASSERT_FALSE(h.message.empty());
  }
}

inline void check_truncations(const std::filesystem::path& dir, const Fixture& fx) {
  const auto path = dir / fx.file;
  for (size_t n = 0; n < fx.bytes.size(); ++n) {
    write_bytes(path, fx.bytes.substr(0, n));
    read_and_check(path);
    if (::testing::Test::HasFatalFailure()) {
      ADD_FAILURE() << "truncated at " << n;
      return;
    }
  }
}

inline void check_flips(const std::filesystem::path& dir, const Fixture& fx, int rounds, uint32_t seed) {
  const auto path = dir / fx.file;
  std::mt19937 rng(seed);
  for (int r = 0; r < rounds; ++r) {
    std::string bytes = fx.bytes;
    const int flips = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < flips && !bytes.empty(); ++k) {
      const size_t at = rng() % bytes.size();
      // Either random garbage or a digit/sign, which keeps numbers parseable but wrong.
      static constexpr char kNear[] = "0123456789-+.e \n";
      bytes[at] = (rng() % 2) ? static_cast<char>(rng() & 0xFF) : kNear[rng() % (sizeof(kNear) - 1)];
    }
    write_bytes(path, bytes);
    read_and_check(path);
    if (::testing::Test::HasFatalFailure()) {
      ADD_FAILURE() << "seed " << seed << " round " << r;
      return;
    }
  }
}

}  // namespace hexpeel::test_io
