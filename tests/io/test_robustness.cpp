// Every reader survives arbitrary bytes: each fixture truncated at every byte and with random
// bytes flipped (fixed seed) reads back as a Status, and an ok result is well formed.
#include "hexpeel/io.h"
#include "io_fixtures.h"
#include "io_robustness.h"

#include <gtest/gtest.h>

namespace hexpeel {
namespace {

std::vector<test_io::Fixture> all_fixtures() {
  std::vector<test_io::Fixture> f = test_io::surface_fixtures();
  HexMesh m;
  for (int v = 0; v < 8; ++v) m.points.push_back(test_io::cube_point(v));
  m.hexes.push_back({0, 1, 2, 3, 4, 5, 6, 7});
  const test_io::ScratchDir scratch_dir("robust_written");
  const auto& dir = scratch_dir.path();
  for (const char* name : {"h.vtk", "h.vtu", "h.mesh", "h.msh"}) {
    EXPECT_TRUE(write_hex_mesh(dir / name, m).ok());
    f.push_back({name, test_io::read_bytes(dir / name)});
  }
  return f;
}

TEST(Robustness, TruncatedFilesNeverCrash) {
  const test_io::ScratchDir scratch_dir("robust_truncate");
  const auto& dir = scratch_dir.path();
  for (const test_io::Fixture& fx : all_fixtures()) {
    SCOPED_TRACE(fx.file);
    test_io::check_truncations(dir, fx);
  }
}

TEST(Robustness, FlippedBytesNeverCrash) {
  const test_io::ScratchDir scratch_dir("robust_flip");
  const auto& dir = scratch_dir.path();
  for (const test_io::Fixture& fx : all_fixtures()) {
    SCOPED_TRACE(fx.file);
    test_io::check_flips(dir, fx, 400, 20240611u);
  }
}

}  // namespace
}  // namespace hexpeel
