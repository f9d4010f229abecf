// Hand-written surface files of every supported format and variant, all describing the same unit
// cube (8 vertices, 6 outward quads), plus helpers to build binary files and temporary paths.
#pragma once

#include "hexpeel/hex_mesh.h"

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>
#include <vector>

namespace hexpeel::test_io {

/// A fixture: a file name (its extension picks the reader) and its bytes.
struct Fixture {
  std::string file;
  std::string bytes;
};

/// Cube corner v (VTK numbering of hex_mesh.h), scaled so coordinates are not all integers.
inline Vec3 cube_point(int v) {
  const double x = (v == 1 || v == 2 || v == 5 || v == 6) ? 0.1 : 0.0;
  const double y = (v == 2 || v == 3 || v == 6 || v == 7) ? 0.25 : 0.0;
  const double z = v >= 4 ? 0.5 : 0.0;
  return {x, y, z};
}

template <class T>
void put(std::string& s, T v, bool big) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (big) {
    for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
  }
  s.append(reinterpret_cast<const char*>(b), sizeof(T));
}

inline std::string ascii_points(const char* prefix, const char* suffix) {
  std::string s;
  char buf[128];
  for (int v = 0; v < 8; ++v) {
    const Vec3 p = cube_point(v);
    std::snprintf(buf, sizeof(buf), "%s%.17g %.17g %.17g%s\n", prefix, p.x(), p.y(), p.z(), suffix);
    s += buf;
  }
  return s;
}

/// The 6 quads, `base`-numbered, each line prefixed and suffixed.
inline std::string ascii_quads(int base, const char* prefix, const char* suffix) {
  std::string s;
  for (const auto& f : kHexFaces) {
    s += prefix;
    for (int k = 0; k < 4; ++k) s += (k ? " " : "") + std::to_string(f[k] + base);
    s += suffix;
    s += '\n';
  }
  return s;
}

inline std::string ply_binary(bool big) {
  std::string s = "ply\nformat ";
  s += big ? "binary_big_endian" : "binary_little_endian";
  s += " 1.0\ncomment made by the test\nelement vertex 8\nproperty double x\nproperty float nx\n"
       "property double y\nproperty double z\nelement face 6\nproperty uchar flags\n"
       "property list uchar int vertex_indices\nelement edge 1\nproperty list ushort uint ids\n"
       "end_header\n";
  for (int v = 0; v < 8; ++v) {
    const Vec3 p = cube_point(v);
    put<double>(s, p.x(), big);
    put<float>(s, 1.0f, big);
    put<double>(s, p.y(), big);
    put<double>(s, p.z(), big);
  }
  for (const auto& f : kHexFaces) {
    put<uint8_t>(s, 7, big);
    put<uint8_t>(s, 4, big);
    for (int c : f) put<int32_t>(s, c, big);
  }
  put<uint16_t>(s, 2, big);
  put<uint32_t>(s, 0, big);
  put<uint32_t>(s, 1, big);
  return s;
}

inline std::string gmsh22_binary() {
  std::string s = "$MeshFormat\n2.2 1 8\n";
  put<int32_t>(s, 1, false);
  s += "\n$EndMeshFormat\n$Nodes\n8\n";
  for (int v = 0; v < 8; ++v) {  // tags 10, 20, ... to exercise the tag map
    put<int32_t>(s, 10 * (v + 1), false);
    for (int k = 0; k < 3; ++k) put<double>(s, cube_point(v)[k], false);
  }
  s += "\n$EndNodes\n$Elements\n7\n";
  put<int32_t>(s, 15, false);  // one point element, then a block of 6 quads
  put<int32_t>(s, 1, false);
  put<int32_t>(s, 2, false);
  put<int32_t>(s, 100, false);
  put<int32_t>(s, 0, false);
  put<int32_t>(s, 0, false);
  put<int32_t>(s, 10, false);
  put<int32_t>(s, 3, false);
  put<int32_t>(s, 6, false);
  put<int32_t>(s, 2, false);
  int id = 1;
  for (const auto& f : kHexFaces) {
    put<int32_t>(s, id++, false);
    put<int32_t>(s, 0, false);
    put<int32_t>(s, 1, false);
    for (int c : f) put<int32_t>(s, 10 * (c + 1), false);
  }
  s += "\n$EndElements\n";
  return s;
}

inline std::string gmsh41_binary() {
  std::string s = "$MeshFormat\n4.1 1 8\n";
  put<int32_t>(s, 1, false);
  s += "\n$EndMeshFormat\n$Entities\n";
  for (int k = 0; k < 4; ++k) put<uint64_t>(s, 0, false);
  s += "\n$EndEntities\n$Nodes\n";
  for (uint64_t v : {1, 8, 1, 8}) put<uint64_t>(s, v, false);
  put<int32_t>(s, 2, false);
  put<int32_t>(s, 1, false);
  put<int32_t>(s, 0, false);
  put<uint64_t>(s, 8, false);
  for (int v = 0; v < 8; ++v) put<uint64_t>(s, static_cast<uint64_t>(v + 1), false);
  for (int v = 0; v < 8; ++v) {
    for (int k = 0; k < 3; ++k) put<double>(s, cube_point(v)[k], false);
  }
  s += "\n$EndNodes\n$Elements\n";
  for (uint64_t v : {1, 6, 1, 6}) put<uint64_t>(s, v, false);
  put<int32_t>(s, 2, false);
  put<int32_t>(s, 1, false);
  put<int32_t>(s, 3, false);
  put<uint64_t>(s, 6, false);
  uint64_t id = 1;
  for (const auto& f : kHexFaces) {
    put<uint64_t>(s, id++, false);
    for (int c : f) put<uint64_t>(s, static_cast<uint64_t>(c + 1), false);
  }
  s += "\n$EndElements\n";
  return s;
}

inline std::string vtk_polydata_binary() {
  std::string s = "# vtk DataFile Version 3.0\ncube\nBINARY\nDATASET POLYDATA\nPOINTS 8 double\n";
  for (int v = 0; v < 8; ++v) {
    for (int k = 0; k < 3; ++k) put<double>(s, cube_point(v)[k], true);
  }
  s += "\nPOLYGONS 6 30\n";
  for (const auto& f : kHexFaces) {
    put<int32_t>(s, 4, true);
    for (int c : f) put<int32_t>(s, c, true);
  }
  s += "\nCELL_DATA 6\nSCALARS id int 1\nLOOKUP_TABLE default\n";
  for (int i = 0; i < 6; ++i) put<int32_t>(s, i, true);
  return s;
}

inline std::string vtk_grid51_binary() {
  std::string s = "# vtk DataFile Version 5.1\ncube\nBINARY\nDATASET UNSTRUCTURED_GRID\n"
                  "POINTS 8 double\n";
  for (int v = 0; v < 8; ++v) {
    for (int k = 0; k < 3; ++k) put<double>(s, cube_point(v)[k], true);
  }
  s += "\nMETADATA\nINFORMATION 0\n\nCELLS 7 24\nOFFSETS vtktypeint64\n";
  for (int64_t i = 0; i <= 6; ++i) put<int64_t>(s, 4 * i, true);
  s += "\nCONNECTIVITY vtktypeint64\n";
  for (const auto& f : kHexFaces) {
    for (int c : f) put<int64_t>(s, c, true);
  }
  s += "\nCELL_TYPES 6\n";
  for (int i = 0; i < 6; ++i) put<int32_t>(s, 9, true);
  s += "\n";
  return s;
}

/// Every surface fixture: the cube in each format and variant.
inline std::vector<Fixture> surface_fixtures() {
  std::vector<Fixture> f;
  // OBJ: comments, ignored statements, slash forms, negative (relative) indices.
  {
    std::string s = "# cube\nmtllib cube.mtl\no cube\n" + ascii_points("v ", "") +
                    "vt 0 0\nvn 0 0 1\ng faces\ns off\nusemtl red\n";
    int n = 0;
    for (const auto& q : kHexFaces) {
      s += "f";
      for (int k = 0; k < 4; ++k) {
        const int i = q[k] + 1;
        switch ((n + k) % 4) {
          case 0: s += " " + std::to_string(i); break;
          case 1: s += " " + std::to_string(i) + "/1"; break;
          case 2: s += " " + std::to_string(i) + "//1"; break;
          default: s += " " + std::to_string(q[k] - 8) + "/1/1"; break;  // relative
        }
      }
      s += n == 2 ? "   # a comment\n" : "\n";
      ++n;
    }
    f.push_back({"cube.obj", s});
  }
  f.push_back({"cube.off", "OFF\n# comment\n8 6 12\n" + ascii_points("", "") + "\n" +
                               ascii_quads(0, "4 ", " 255 0 0")});
  f.push_back({"cube_color.off", "COFF 8 6 0\n" + ascii_points("", " 1 0 0 1") + ascii_quads(0, "4 ", "")});
  f.push_back({"cube_ascii.ply",
               "ply\nformat ascii 1.0\nelement vertex 8\nproperty float64 x\nproperty float64 y\n"
               "property float64 z\nproperty uchar red\nelement face 6\n"
               "property list uint8 uint32 vertex_index\nend_header\n" +
                   ascii_points("", " 200") + ascii_quads(0, "4 ", "")});
  f.push_back({"cube_le.ply", ply_binary(false)});
  f.push_back({"cube_be.ply", ply_binary(true)});
  f.push_back({"cube.mesh", "MeshVersionFormatted 2\n# comment\nDimension\n3\nVertices\n8\n" +
                                ascii_points("", " 0") + "Corners\n2\n1\n2\nEdges 1\n1 2 0\n"
                                "Quadrilaterals\n6\n" + ascii_quads(1, "", " 3") + "End\n"});
  {
    std::string nodes, elems;
    for (int v = 0; v < 8; ++v) {
      char buf[128];
      const Vec3 p = cube_point(v);
      std::snprintf(buf, sizeof(buf), "%d %.17g %.17g %.17g\n", v + 1, p.x(), p.y(), p.z());
      nodes += buf;
    }
    int id = 1;
    for (const auto& q : kHexFaces) {
      elems += std::to_string(id++) + " 3 2 1 1";
      for (int c : q) elems += " " + std::to_string(c + 1);
      elems += "\n";
    }
    f.push_back({"cube22.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n2 1 \"skin\"\n"
                               "$EndPhysicalNames\n$Nodes\n8\n" + nodes + "$EndNodes\n$Elements\n6\n" +
                               elems + "$EndElements\n$NodeData\n1\n\"x\"\n$EndNodeData\n"});
    std::string n41 = "$Nodes\n1 8 1 8\n2 1 0 8\n";
    for (int v = 1; v <= 8; ++v) n41 += std::to_string(v) + "\n";
    n41 += ascii_points("", "") + "$EndNodes\n";
    std::string e41 = "$Elements\n1 6 1 6\n2 1 3 6\n";
    id = 1;
    for (const auto& q : kHexFaces) {
      e41 += std::to_string(id++);
      for (int c : q) e41 += " " + std::to_string(c + 1);
      e41 += "\n";
    }
    e41 += "$EndElements\n";
    f.push_back({"cube41.msh", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 1 0\n"
                               "1 0 0 0 1 1 1 0 0\n$EndEntities\n" + n41 + e41});
  }
  f.push_back({"cube22b.msh", gmsh22_binary()});
  f.push_back({"cube41b.msh", gmsh41_binary()});
  f.push_back({"cube_poly.vtk", "# vtk DataFile Version 3.0\ncube\nASCII\nDATASET POLYDATA\n"
                                "POINTS 8 double\n" + ascii_points("", "") + "POLYGONS 6 30\n" +
                                    ascii_quads(0, "4 ", "") + "POINT_DATA 8\n"});
  f.push_back({"cube_grid.vtk", "# vtk DataFile Version 4.2\ncube\nASCII\nDATASET UNSTRUCTURED_GRID\n"
                                "POINTS 8 double\n" + ascii_points("", "") + "CELLS 7 32\n1 0\n" +
                                    ascii_quads(0, "4 ", "") + "CELL_TYPES 7\n1\n9\n9\n7\n9\n9\n9\n"});
  f.push_back({"cube_polyb.vtk", vtk_polydata_binary()});
  f.push_back({"cube_grid51b.vtk", vtk_grid51_binary()});
  f.push_back({"cube.vtu",
               "<?xml version=\"1.0\"?>\n<!-- a comment -->\n"
               "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
               "<UnstructuredGrid>\n<Piece NumberOfPoints=\"8\" NumberOfCells=\"6\">\n"
               "<PointData></PointData>\n<Points>\n"
               "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n" +
                   ascii_points("", "") + "</DataArray>\n</Points>\n<Cells>\n"
                   "<DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n" +
                   ascii_quads(0, "", "") +
                   "</DataArray>\n<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n"
                   "4 8 12 16 20 24\n</DataArray>\n"
                   "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n9 9 9 9 9 9\n"
                   "</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n"});
  return f;
}

/// A scratch directory for one test (unique per process), removed with everything in it.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& test)
      : path_(std::filesystem::temp_directory_path() /
              ("hexpeel_test_io_" + std::to_string(::getpid()) + "_" + test)) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline void write_bytes(const std::filesystem::path& path, const std::string& bytes) {
  // A fresh file rather than a truncated one: some file systems flush on truncate-and-rewrite.
  std::filesystem::remove(path);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

inline std::string read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace hexpeel::test_io
