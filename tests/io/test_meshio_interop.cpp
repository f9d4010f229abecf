// Interoperability with meshio and VTK (independent readers and writers), when /usr/bin/python3
// has them: files they write in every variant read back as the same mesh with our readers, and
// every file we write reads back in them as the same mesh. Skipped when they are not installed.
#include "hexpeel/io.h"
#include "io_fixtures.h"
#include "io_robustness.h"

#include <gtest/gtest.h>

#include <cstdlib>

namespace hexpeel {
namespace {

bool have_meshio() {
  return std::system("/usr/bin/python3 -c 'import meshio' > /dev/null 2>&1") == 0;
}

/// The mesh the Python scripts build too.
HexMesh reference_mesh() {
  HexMesh m;
  const double pts[12][3] = {{0, 0, 0}, {0.1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1},
                             {1, 1, 1}, {0, 1, 1}, {2, 0, 0}, {2, 1.0 / 3.0, 0}, {2, 0, 1}, {2, 1, 1}};
  for (const auto& p : pts) m.points.emplace_back(p[0], p[1], p[2]);
  m.hexes.push_back({0, 1, 2, 3, 4, 5, 6, 7});
  m.hexes.push_back({1, 8, 9, 2, 5, 10, 11, 6});
  return m;
}

constexpr const char* kPythonMesh =
    "import sys, meshio, numpy as np\n"
    "pts = np.array([[0,0,0],[0.1,0,0],[1,1,0],[0,1,0],[0,0,1],[1,0,1],[1,1,1],[0,1,1],\n"
    "                [2,0,0],[2,1.0/3.0,0],[2,0,1],[2,1,1]], dtype=float)\n"
    "hexes = np.array([[0,1,2,3,4,5,6,7],[1,8,9,2,5,10,11,6]])\n"
    "d = sys.argv[1]\n";

int run_python(const std::filesystem::path& dir, const std::string& name, const std::string& body) {
  const auto script = dir / name;
  test_io::write_bytes(script, std::string(kPythonMesh) + body);
  const std::string cmd = "/usr/bin/python3 '" + script.string() + "' '" + dir.string() + "' > '" +
                          (dir / (name + ".log")).string() + "' 2>&1";
  return std::system(cmd.c_str());
}

TEST(MeshioInterop, ReadsMeshioFiles) {
  if (!have_meshio()) GTEST_SKIP() << "/usr/bin/python3 cannot import meshio";
  const test_io::ScratchDir scratch_dir("meshio_read");
  const auto& dir = scratch_dir.path();
  const std::string body =
      "m = meshio.Mesh(pts, [('hexahedron', hexes)])\n"
      "w = lambda n, **k: meshio.write(d + '/' + n, m, **k)\n"
      "w('a_bin51.vtk')\n"
      "w('a_ascii51.vtk', binary=False)\n"
      "from meshio.vtk import _vtk_42\n"  // the 4.2 layout has no public switch in meshio 5.0
      "_vtk_42.write(d + '/a_bin42.vtk', m, binary=True)\n"
      "_vtk_42.write(d + '/a_ascii42.vtk', m, binary=False)\n"
      "w('a_zlib.vtu')\n"
      "w('a_raw.vtu', compression=None)\n"
      "w('a_zlib64.vtu', header_type='UInt64')\n"
      "w('a_raw64.vtu', compression=None, header_type='UInt64')\n"
      "w('a_ascii.vtu', binary=False)\n"
      "w('a_bin41.msh', file_format='gmsh')\n"
      "w('a_ascii41.msh', file_format='gmsh', binary=False)\n"
      "w('a_bin22.msh', file_format='gmsh22')\n"
      "w('a_ascii22.msh', file_format='gmsh22', binary=False)\n"
      "w('a.mesh')\n";
  ASSERT_EQ(run_python(dir, "write.py", body), 0) << test_io::read_bytes(dir / "write.py.log");
  const HexMesh ref = reference_mesh();
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const auto& path = entry.path();
    if (!is_hex_mesh_extension(path)) continue;
    ++files;
    HexMesh mesh;
    int64_t others = 0;
    const Status s = read_hex_mesh(path, mesh, &others);
    ASSERT_TRUE(s.ok()) << path << ": " << to_string(s);
    // meshio prints ASCII .vtu with 12 significant digits; every other variant is exact.
    const double tol = path.filename() == "a_ascii.vtu" ? 1e-11 : 0.0;
    ASSERT_EQ(mesh.points.size(), ref.points.size()) << path;
    for (size_t v = 0; v < ref.points.size(); ++v) {
      EXPECT_LE((mesh.points[v] - ref.points[v]).cwiseAbs().maxCoeff(), tol) << path << " point " << v;
    }
    EXPECT_EQ(mesh.hexes, ref.hexes) << path;
    EXPECT_EQ(others, 0) << path;
  }
  EXPECT_EQ(files, 14);
}

TEST(MeshioInterop, MeshioFilesSurviveDamage) {
  if (!have_meshio()) GTEST_SKIP() << "/usr/bin/python3 cannot import meshio";
  const test_io::ScratchDir scratch_dir("meshio_damage");
  const auto& dir = scratch_dir.path();
  const std::string body =
      "m = meshio.Mesh(pts, [('hexahedron', hexes)])\n"
      "meshio.write(d + '/z.vtu', m)\n"
      "meshio.write(d + '/b.vtk', m)\n"
      "meshio.write(d + '/b.msh', m, file_format='gmsh')\n";
  ASSERT_EQ(run_python(dir, "write.py", body), 0) << test_io::read_bytes(dir / "write.py.log");
  const test_io::ScratchDir scratch_work("meshio_damage_work");
  const auto& work = scratch_work.path();
  for (const char* name : {"z.vtu", "b.vtk", "b.msh"}) {
    SCOPED_TRACE(name);
    const test_io::Fixture fx{name, test_io::read_bytes(dir / name)};
    test_io::check_truncations(work, fx);
    test_io::check_flips(work, fx, 300, 77u);
  }
}

TEST(MeshioInterop, MeshioReadsOurFiles) {
  if (!have_meshio()) GTEST_SKIP() << "/usr/bin/python3 cannot import meshio";
  const test_io::ScratchDir scratch_dir("meshio_write");
  const auto& dir = scratch_dir.path();
  const HexMesh ref = reference_mesh();
  for (const char* name : {"o.vtk", "o.vtu", "o.mesh", "o.msh"}) {
    ASSERT_TRUE(write_hex_mesh(dir / name, ref).ok()) << name;
  }
  const std::string body =
      "fmt = {'o.vtk': 'vtk', 'o.vtu': 'vtu', 'o.mesh': 'medit', 'o.msh': 'gmsh'}\n"
      "for n, f in fmt.items():\n"
      "    r = meshio.read(d + '/' + n, file_format=f)\n"
      "    assert np.array_equal(r.points, pts), n\n"
      "    hx = [c.data for c in r.cells if c.type == 'hexahedron']\n"
      "    assert len(hx) == 1 and np.array_equal(hx[0], hexes), n\n"
      "    assert all(c.type == 'hexahedron' for c in r.cells), n\n";
  EXPECT_EQ(run_python(dir, "read.py", body), 0) << test_io::read_bytes(dir / "read.py.log");
}

bool have_vtk() {
  return std::system("/usr/bin/python3 -c 'import vtk' > /dev/null 2>&1") == 0;
}

constexpr const char* kPythonVtkGrid =
    "import vtk\n"
    "def grid():\n"
    "    g = vtk.vtkUnstructuredGrid()\n"
    "    p = vtk.vtkPoints()\n"
    "    p.SetDataTypeToDouble()\n"
    "    for q in pts: p.InsertNextPoint(*q)\n"
    "    g.SetPoints(p)\n"
    "    for h in hexes:\n"
    "        ids = vtk.vtkIdList()\n"
    "        for v in h: ids.InsertNextId(int(v))\n"
    "        g.InsertNextCell(vtk.VTK_HEXAHEDRON, ids)\n"
    "    return g\n";

TEST(VtkInterop, ReadsVtkWrittenFiles) {
  if (!have_vtk()) GTEST_SKIP() << "/usr/bin/python3 cannot import vtk";
  const test_io::ScratchDir scratch_dir("vtk_read");
  const auto& dir = scratch_dir.path();
  const std::string body = std::string(kPythonVtkGrid) +
      "def xml(name, setup):\n"
      "    w = vtk.vtkXMLUnstructuredGridWriter()\n"
      "    w.SetInputData(grid())\n"
      "    w.SetFileName(d + '/' + name)\n"
      "    setup(w)\n"
      "    assert w.Write() == 1\n"
      "xml('appended_raw_zlib.vtu', lambda w: None)\n"
      "xml('appended_b64.vtu', lambda w: (w.EncodeAppendedDataOn(), w.SetCompressorTypeToNone()))\n"
      "xml('appended_b64_zlib64.vtu', lambda w: (w.EncodeAppendedDataOn(), w.SetHeaderTypeToUInt64()))\n"
      "xml('inline_zlib.vtu', lambda w: w.SetDataModeToBinary())\n"
      "xml('inline_raw64.vtu', lambda w: (w.SetDataModeToBinary(), w.SetCompressorTypeToNone(), w.SetHeaderTypeToUInt64()))\n"
      "xml('ascii.vtu', lambda w: w.SetDataModeToAscii())\n"
      "for name, binary in (('legacy_bin.vtk', True), ('legacy_ascii.vtk', False)):\n"
      "    w = vtk.vtkUnstructuredGridWriter()\n"
      "    w.SetInputData(grid())\n"
      "    w.SetFileName(d + '/' + name)\n"
      "    w.SetFileTypeToBinary() if binary else w.SetFileTypeToASCII()\n"
      "    assert w.Write() == 1\n";
  ASSERT_EQ(run_python(dir, "write.py", body), 0) << test_io::read_bytes(dir / "write.py.log");
  const HexMesh ref = reference_mesh();
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const auto& path = entry.path();
    if (!is_hex_mesh_extension(path)) continue;
    ++files;
    HexMesh mesh;
    const Status s = read_hex_mesh(path, mesh);
    ASSERT_TRUE(s.ok()) << path << ": " << to_string(s);
    // VTK prints ASCII with fewer digits than a round trip needs.
    const double tol = path.filename().string().find("ascii") != std::string::npos ? 1e-6 : 0.0;
    ASSERT_EQ(mesh.points.size(), ref.points.size()) << path;
    for (size_t v = 0; v < ref.points.size(); ++v) {
      EXPECT_LE((mesh.points[v] - ref.points[v]).cwiseAbs().maxCoeff(), tol) << path << " point " << v;
    }
    EXPECT_EQ(mesh.hexes, ref.hexes) << path;
  }
  EXPECT_EQ(files, 8);
}

TEST(VtkInterop, VtkReadsOurFiles) {
  if (!have_vtk()) GTEST_SKIP() << "/usr/bin/python3 cannot import vtk";
  const test_io::ScratchDir scratch_dir("vtk_write");
  const auto& dir = scratch_dir.path();
  const HexMesh ref = reference_mesh();
  for (const char* name : {"o.vtk", "o.vtu"}) ASSERT_TRUE(write_hex_mesh(dir / name, ref).ok()) << name;
  const std::string body =
      "import vtk\n"
      "from vtk.util.numpy_support import vtk_to_numpy\n"
      "for name, reader in (('o.vtk', vtk.vtkUnstructuredGridReader()),\n"
      "                     ('o.vtu', vtk.vtkXMLUnstructuredGridReader())):\n"
      "    reader.SetFileName(d + '/' + name)\n"
      "    reader.Update()\n"
      "    g = reader.GetOutput()\n"
      "    assert np.array_equal(vtk_to_numpy(g.GetPoints().GetData()), pts), name\n"
      "    assert g.GetNumberOfCells() == 2, name\n"
      "    for c in range(2):\n"
      "        assert g.GetCellType(c) == vtk.VTK_HEXAHEDRON, name\n"
      "        ids = g.GetCell(c).GetPointIds()\n"
      "        assert [ids.GetId(k) for k in range(8)] == list(hexes[c]), name\n";
  EXPECT_EQ(run_python(dir, "read.py", body), 0) << test_io::read_bytes(dir / "read.py.log");
}

}  // namespace
}  // namespace hexpeel
