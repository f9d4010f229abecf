// Surface readers: every format and variant reads the same cube; errors name file and line.
#include "hexpeel/io.h"
#include "io_fixtures.h"

#include <gtest/gtest.h>

namespace hexpeel {
namespace {

using test_io::Fixture;

void expect_cube(const PolygonSoup& soup, const std::string& file) {
  ASSERT_EQ(soup.points.size(), 8u) << file;
  for (int v = 0; v < 8; ++v) EXPECT_EQ(soup.points[v], test_io::cube_point(v)) << file << " vertex " << v;
  ASSERT_EQ(soup.num_faces(), 6) << file;
  for (int f = 0; f < 6; ++f) {
    ASSERT_EQ(soup.face_size(f), 4) << file;
    for (int k = 0; k < 4; ++k) {
      EXPECT_EQ(soup.indices[soup.offsets[f] + k], kHexFaces[f][k]) << file << " face " << f;
    }
  }
}

TEST(SurfaceReaders, EveryFormatReadsTheCube) {
  const test_io::ScratchDir scratch_dir("surface_formats");
  const auto& dir = scratch_dir.path();
  for (const Fixture& fx : test_io::surface_fixtures()) {
    const auto path = dir / fx.file;
    test_io::write_bytes(path, fx.bytes);
    ASSERT_TRUE(is_surface_extension(path)) << fx.file;
    PolygonSoup soup;
    const Status s = read_surface(path, soup);
    ASSERT_TRUE(s.ok()) << fx.file << ": " << to_string(s);
    expect_cube(soup, fx.file);
  }
}

TEST(SurfaceReaders, TrianglesAndPolygonsAreKeptForValidation) {
  const test_io::ScratchDir scratch_dir("surface_polygons");
  const auto& dir = scratch_dir.path();
  test_io::write_bytes(dir / "mixed.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\n"
                                          "f 1 2 3\nf 1 2 3 4 5\n");
  PolygonSoup soup;
  ASSERT_TRUE(read_surface(dir / "mixed.obj", soup).ok());
  ASSERT_EQ(soup.num_faces(), 2);
  EXPECT_EQ(soup.face_size(0), 3);
  EXPECT_EQ(soup.face_size(1), 5);

  test_io::write_bytes(dir / "tri.mesh", "MeshVersionFormatted 1\nDimension 3\nVertices 3\n"
                                         "0 0 0 1\n1 0 0 1\n0 1 0 1\nTriangles 1\n1 2 3 0\nEnd\n");
  ASSERT_TRUE(read_surface(dir / "tri.mesh", soup).ok());
  ASSERT_EQ(soup.num_faces(), 1);
  EXPECT_EQ(soup.face_size(0), 3);
}

TEST(SurfaceReaders, OutOfRangeIndexNamesFileAndLine) {
  const test_io::ScratchDir scratch_dir("surface_range");
  const auto& dir = scratch_dir.path();
  const auto path = dir / "cube.obj";
  test_io::write_bytes(path, "v 0 0 0\nv 1 0 0\nv 1 1 0\n# c\nf 1 2 99\n");
  PolygonSoup soup;
  const Status s = read_surface(path, soup);
  EXPECT_EQ(s.code, StatusCode::index_out_of_range);
  EXPECT_NE(s.message.find("cube.obj:5:"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("vertex 99 but only 3 vertices exist"), std::string::npos) << s.message;
  EXPECT_EQ(soup.num_faces(), 0);

  test_io::write_bytes(dir / "bad.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n");
  EXPECT_EQ(read_surface(dir / "bad.off", soup).code, StatusCode::index_out_of_range);
}

TEST(SurfaceReaders, SyntaxErrorsNameTheLine) {
  const test_io::ScratchDir scratch_dir("surface_syntax");
  const auto& dir = scratch_dir.path();
  test_io::write_bytes(dir / "a.off", "OFF\n2 0 0\n0 0 0\n1 x 0\n");
  PolygonSoup soup;
  Status s = read_surface(dir / "a.off", soup);
  EXPECT_EQ(s.code, StatusCode::parse_error);
  EXPECT_NE(s.message.find("a.off:4:"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("'x'"), std::string::npos) << s.message;

  test_io::write_bytes(dir / "huge.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n"
                                         "property float x\nproperty float y\nproperty float z\nend_header\n");
  s = read_surface(dir / "huge.ply", soup);
  EXPECT_EQ(s.code, StatusCode::parse_error);
  EXPECT_NE(s.message.find("more than the rest of the file"), std::string::npos) << s.message;

  test_io::write_bytes(dir / "neg.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n-5\n$EndNodes\n");
  EXPECT_EQ(read_surface(dir / "neg.msh", soup).code, StatusCode::parse_error);
}

TEST(SurfaceReaders, ObjOfAnotherFormatSaysSo) {
  const test_io::ScratchDir scratch_dir("surface_not_obj");
  const auto& dir = scratch_dir.path();
  PolygonSoup soup;
  // plain text, an OFF file and binary bytes given the .obj extension: the line is named
  test_io::write_bytes(dir / "text.obj", "# fine\nv 0 0 0\nhello world\n");
  Status s = read_surface(dir / "text.obj", soup);
  EXPECT_EQ(s.code, StatusCode::parse_error);
  EXPECT_NE(s.message.find("text.obj:3:"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("'hello'; is this an OBJ file?"), std::string::npos) << s.message;
  test_io::write_bytes(dir / "off.obj", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  s = read_surface(dir / "off.obj", soup);
  EXPECT_EQ(s.code, StatusCode::parse_error);
  EXPECT_NE(s.message.find("off.obj:1:"), std::string::npos) << s.message;
  test_io::write_bytes(dir / "bin.obj", std::string("\x7f" "ELF\x02\x01\x01\0\0\0", 10));
  s = read_surface(dir / "bin.obj", soup);
  EXPECT_EQ(s.code, StatusCode::parse_error);
  EXPECT_NE(s.message.find("is this an OBJ file?"), std::string::npos) << s.message;
  // every statement of the format is still accepted and ignored
  test_io::write_bytes(dir / "full.obj",
                       "mtllib a.mtl\no part\ng side\ns 1\nusemtl steel\nv 0 0 0\nv 1 0 0\n"
                       "v 1 1 0\nvt 0 0\nvn 0 0 1\nvp 0.5\nl 1 2\nf 1/1/1 2/1/1 3/1/1\n");
  s = read_surface(dir / "full.obj", soup);
  EXPECT_TRUE(s.ok()) << to_string(s);
  EXPECT_EQ(soup.num_faces(), 1);
}

TEST(SurfaceReaders, EmptyAndUnknownFiles) {
  const test_io::ScratchDir scratch_dir("surface_empty");
  const auto& dir = scratch_dir.path();
  test_io::write_bytes(dir / "empty.obj", "");
  PolygonSoup soup;
  Status s = read_surface(dir / "empty.obj", soup);
  EXPECT_EQ(s.code, StatusCode::empty_mesh);
  EXPECT_NE(s.message.find("empty"), std::string::npos);

  test_io::write_bytes(dir / "points.obj", "v 0 0 0\n");
  EXPECT_EQ(read_surface(dir / "points.obj", soup).code, StatusCode::empty_mesh);

  test_io::write_bytes(dir / "cube.stl", "solid x\n");
  s = read_surface(dir / "cube.stl", soup);
  EXPECT_EQ(s.code, StatusCode::unsupported_format);
  EXPECT_NE(s.message.find(".obj"), std::string::npos) << s.message;
  EXPECT_FALSE(is_surface_extension("x.stl"));
  EXPECT_TRUE(is_surface_extension("X.OBJ"));

  EXPECT_EQ(read_surface(dir / "missing.obj", soup).code, StatusCode::io_error);
}

// A volume mesh given as the surface: its hexahedra are not the surface; with no faces beside
// them the error says what the file holds.
TEST(SurfaceReaders, HexahedraAreNotTheSurface) {
  const test_io::ScratchDir scratch_dir("surface_hexes");
  const auto& dir = scratch_dir.path();
  const std::string head = "# vtk DataFile Version 4.2\nx\nASCII\nDATASET UNSTRUCTURED_GRID\n"
                           "POINTS 8 double\n0 0 0 1 0 0 1 1 0 0 1 0 0 0 1 1 0 1 1 1 1 0 1 1\n";
  test_io::write_bytes(dir / "hex.vtk", head + "CELLS 1 9\n8 0 1 2 3 4 5 6 7\nCELL_TYPES 1\n12\n");
  PolygonSoup soup;
  int64_t hexes = -1;
  const Status s = read_surface(dir / "hex.vtk", soup, &hexes);
  EXPECT_EQ(s.code, StatusCode::empty_mesh);
  EXPECT_NE(s.message.find("1 hexahedra and no surface faces"), std::string::npos) << s.message;
  EXPECT_EQ(hexes, 0);  // nothing read

  test_io::write_bytes(dir / "both.vtk",
                       head + "CELLS 7 39\n8 0 1 2 3 4 5 6 7\n4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n"
                              "4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\nCELL_TYPES 7\n12\n9\n9\n9\n9\n9\n9\n");
  ASSERT_TRUE(read_surface(dir / "both.vtk", soup, &hexes).ok());
  EXPECT_EQ(hexes, 1);
  EXPECT_EQ(soup.num_faces(), 6);
}

TEST(SurfaceReaders, UnsupportedVariantsSaySo) {
  const test_io::ScratchDir scratch_dir("surface_variants");
  const auto& dir = scratch_dir.path();
  test_io::write_bytes(dir / "old.msh", "$MeshFormat\n4.0 0 8\n$EndMeshFormat\n");
  PolygonSoup soup;
  EXPECT_EQ(read_surface(dir / "old.msh", soup).code, StatusCode::unsupported_format);
  test_io::write_bytes(dir / "lz.vtu", "<VTKFile type=\"UnstructuredGrid\" compressor=\"vtkLZ4DataCompressor\">");
  EXPECT_EQ(read_surface(dir / "lz.vtu", soup).code, StatusCode::unsupported_format);
  test_io::write_bytes(dir / "sp.vtk", "# vtk DataFile Version 3.0\nx\nASCII\nDATASET STRUCTURED_POINTS\n");
  EXPECT_EQ(read_surface(dir / "sp.vtk", soup).code, StatusCode::unsupported_format);
}

TEST(SurfaceWriters, ObjAndOffRoundTrip) {
  const test_io::ScratchDir scratch_dir("surface_write");
  const auto& dir = scratch_dir.path();
  QuadSurface cube;
  for (int v = 0; v < 8; ++v) cube.points.push_back(test_io::cube_point(v) * (1.0 / 3.0));
  for (const auto& f : kHexFaces) cube.quads.push_back({f[0], f[1], f[2], f[3]});
  for (const char* name : {"s.obj", "s.off"}) {
    ASSERT_TRUE(write_surface(dir / name, cube).ok()) << name;
    PolygonSoup soup;
    ASSERT_TRUE(read_surface(dir / name, soup).ok()) << name;
    ASSERT_EQ(soup.points, cube.points) << name;
    ASSERT_EQ(soup.num_faces(), 6);
    for (int f = 0; f < 6; ++f) {
      for (int k = 0; k < 4; ++k) EXPECT_EQ(soup.indices[4 * f + k], cube.quads[f][k]);
    }
  }
  EXPECT_EQ(write_surface(dir / "s.ply", cube).code, StatusCode::unsupported_format);
}

}  // namespace
}  // namespace hexpeel
