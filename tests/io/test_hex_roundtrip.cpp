// Hex mesh writers: each round-trips through its reader exactly, deterministically; failed
// writes leave nothing behind.
#include "hexpeel/io.h"
#include "io_fixtures.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace hexpeel {
namespace {

/// Two hexes sharing a face, with coordinates that need all 17 digits.
HexMesh two_hexes() {
  HexMesh m;
  for (int v = 0; v < 8; ++v) m.points.push_back(test_io::cube_point(v) / 3.0);
  for (int v = 4; v < 8; ++v) m.points.push_back(test_io::cube_point(v) + Vec3(1e-300, std::nextafter(0.5, 1.0), -2.5e10));
  m.hexes.push_back({0, 1, 2, 3, 4, 5, 6, 7});
  m.hexes.push_back({4, 5, 6, 7, 8, 9, 10, 11});
  return m;
}

TEST(HexWriters, RoundTripExactly) {
  const test_io::ScratchDir scratch_dir("hex_roundtrip");
  const auto& dir = scratch_dir.path();
  const HexMesh mesh = two_hexes();
  for (const char* name : {"m.vtk", "m.vtu", "m.mesh", "m.msh"}) {
    const auto path = dir / name;
    ASSERT_TRUE(is_hex_mesh_extension(path));
    const Status w = write_hex_mesh(path, mesh);
    ASSERT_TRUE(w.ok()) << name << ": " << to_string(w);
    HexMesh back;
    const Status r = read_hex_mesh(path, back);
    ASSERT_TRUE(r.ok()) << name << ": " << to_string(r);
    EXPECT_EQ(back.points, mesh.points) << name;
    EXPECT_EQ(back.hexes, mesh.hexes) << name;
    // Byte-for-byte determinism.
    const std::string first = test_io::read_bytes(path);
    ASSERT_TRUE(write_hex_mesh(path, mesh).ok());
    EXPECT_EQ(test_io::read_bytes(path), first) << name;
  }
}

TEST(HexReaders, OtherCellsAreCountedOrRejected) {
  const test_io::ScratchDir scratch_dir("hex_others");
  const auto& dir = scratch_dir.path();
  const auto path = dir / "mixed.msh";
  std::string s = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n8\n";
  for (int v = 0; v < 8; ++v) {
    const Vec3 p = test_io::cube_point(v);
    s += std::to_string(v + 1) + " " + std::to_string(p.x()) + " " + std::to_string(p.y()) + " " +
         std::to_string(p.z()) + "\n";
  }
  s += "$EndNodes\n$Elements\n3\n1 3 2 0 1 1 4 3 2\n2 5 2 0 1 1 2 3 4 5 6 7 8\n3 15 2 0 1 1\n$EndElements\n";
  test_io::write_bytes(path, s);
  HexMesh mesh;
  const Status strict = read_hex_mesh(path, mesh);
  EXPECT_EQ(strict.code, StatusCode::invalid_mesh);
  EXPECT_NE(strict.message.find("mixed.msh:17:"), std::string::npos) << strict.message;
  int64_t others = 0;
  ASSERT_TRUE(read_hex_mesh(path, mesh, &others).ok());
  EXPECT_EQ(others, 2);
  ASSERT_EQ(mesh.num_hexes(), 1);
  EXPECT_EQ(mesh.hexes[0], (Hex{0, 1, 2, 3, 4, 5, 6, 7}));

  test_io::write_bytes(dir / "nohex.vtk", "# vtk DataFile Version 4.2\nx\nASCII\nDATASET UNSTRUCTURED_GRID\n"
                                          "POINTS 1 float\n0 0 0\nCELLS 1 2\n1 0\nCELL_TYPES 1\n1\n");
  EXPECT_EQ(read_hex_mesh(dir / "nohex.vtk", mesh, &others).code, StatusCode::empty_mesh);

  test_io::write_bytes(dir / "bad.mesh", "MeshVersionFormatted 2\nDimension 3\nVertices 1\n0 0 0 0\n"
                                         "Hexahedra 1\n1 2 3 4 5 6 7 8 0\nEnd\n");
  const Status bad = read_hex_mesh(dir / "bad.mesh", mesh);
  EXPECT_EQ(bad.code, StatusCode::invalid_mesh);
  EXPECT_NE(bad.message.find("bad.mesh:6:"), std::string::npos) << bad.message;

  EXPECT_EQ(read_hex_mesh(dir / "x.obj", mesh).code, StatusCode::unsupported_format);
  EXPECT_FALSE(is_hex_mesh_extension("x.obj"));
}

TEST(HexReaders, VoxelCellsAreReordered) {
  const test_io::ScratchDir scratch_dir("hex_voxel");
  const auto& dir = scratch_dir.path();
  test_io::write_bytes(dir / "v.vtk", "# vtk DataFile Version 4.2\nx\nASCII\nDATASET UNSTRUCTURED_GRID\n"
                                      "POINTS 8 double\n0 0 0 1 0 0 0 1 0 1 1 0 0 0 1 1 0 1 0 1 1 1 1 1\n"
                                      "CELLS 1 9\n8 0 1 2 3 4 5 6 7\nCELL_TYPES 1\n11\n");
  HexMesh mesh;
  ASSERT_TRUE(read_hex_mesh(dir / "v.vtk", mesh).ok());
  EXPECT_EQ(mesh.hexes[0], (Hex{0, 1, 3, 2, 4, 5, 7, 6}));
}

TEST(Writers, FailedWriteLeavesNoFile) {
  const test_io::ScratchDir scratch_dir("failed_write");
  const auto& dir = scratch_dir.path();
  const HexMesh mesh = two_hexes();
  const auto missing = dir / "no_such_dir" / "m.vtk";
  const Status s = write_hex_mesh(missing, mesh);
  EXPECT_EQ(s.code, StatusCode::io_error);
  EXPECT_NE(s.message.find("no_such_dir"), std::string::npos) << s.message;
  EXPECT_FALSE(std::filesystem::exists(missing));

  // The target is a directory: the rename fails and the temporary file is removed.
  std::filesystem::create_directories(dir / "taken.vtu");
  EXPECT_EQ(write_hex_mesh(dir / "taken.vtu", mesh).code, StatusCode::io_error);
  int entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1);  // only taken.vtu itself

  EXPECT_EQ(write_text_file(dir / "nope" / "r.txt", "x").code, StatusCode::io_error);
  ASSERT_TRUE(write_text_file(dir / "r.txt", "report\n").ok());
  EXPECT_EQ(test_io::read_bytes(dir / "r.txt"), "report\n");
  EXPECT_EQ(write_hex_mesh(dir / "m.stl", mesh).code, StatusCode::unsupported_format);
}

}  // namespace
}  // namespace hexpeel
