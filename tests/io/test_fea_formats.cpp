// The FEA output formats, Abaqus / CalculiX .inp and Exodus II .exo / .e, read back by readers
// independent of ours: meshio for nodes, hexes and node sets, plain text parsing (the .inp
// surface) and netCDF4 (the Exodus side set) for the boundary faces, with the face numbering
// tables taken from the Abaqus and Exodus manuals. The expected boundary is the generator's
// surface, not anything the writers computed. Skipped when /usr/bin/python3 lacks the modules.
#include "hexpeel/io.h"
#include "io_fixtures.h"
#include "support/generators.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace hexpeel {
namespace {

bool python_has(const char* modules) {
  const std::string cmd =
      std::string("/usr/bin/python3 -c 'import ") + modules + "' > /dev/null 2>&1";
  return std::system(cmd.c_str()) == 0;
}

/// Runs `body` as a script with arguments `dir` and `args`; its output goes to <script>.log.
int run_python(const std::filesystem::path& dir, const std::string& name, const std::string& body,
               const std::string& args) {
  const auto script = dir / name;
  test_io::write_bytes(script, body);
  const std::string cmd = "/usr/bin/python3 '" + script.string() + "' '" + dir.string() + "' " +
                          args + " > '" + (dir / (name + ".log")).string() + "' 2>&1";
  return std::system(cmd.c_str());
}

/// The meshes written: a grid, a cubed sphere (curved, irrational coordinates) and a pillowed
/// cubed sphere (irregular vertex valences, boundary hexes with several boundary faces).
std::vector<testing::Generated> cases() {
  std::vector<testing::Generated> out;
  out.push_back(testing::cube(2, 3, 4));
  out.back().name = "cube234";
  out.push_back(testing::cubed_sphere(3));
  out.back().name = "sphere3";
  out.push_back(testing::pillowed(testing::cubed_sphere(3), 5));
  out.back().name = "pillowed_sphere3";
  return out;
}

/// What the Python checks compare against: <name>.points.txt (%.17g, exact), <name>.hexes.txt
/// and <name>.quads.txt (the generator's surface, 0-based ids of the mesh's points).
void write_expected(const std::filesystem::path& dir, const testing::Generated& g) {
  std::string points, hexes, quads;
  char buf[96];
  for (const Vec3& p : g.known_mesh.points) {
    std::snprintf(buf, sizeof(buf), "%.17g %.17g %.17g\n", p.x(), p.y(), p.z());
    points += buf;
  }
  for (const Hex& h : g.known_mesh.hexes) {
    for (int k = 0; k < 8; ++k) hexes += std::to_string(h[k]) + (k < 7 ? " " : "\n");
  }
  for (const Quad& q : g.surface.quads) {
    for (int k = 0; k < 4; ++k) quads += std::to_string(q[k]) + (k < 3 ? " " : "\n");
  }
  test_io::write_bytes(dir / (g.name + ".points.txt"), points);
  test_io::write_bytes(dir / (g.name + ".hexes.txt"), hexes);
  test_io::write_bytes(dir / (g.name + ".quads.txt"), quads);
}

/// Writes every case as `<name><ext>` with its expected data; returns the names as arguments.
std::string write_cases(const std::filesystem::path& dir, const std::string& ext) {
  std::string args;
  for (const testing::Generated& g : cases()) {
    // The premises: a valid known mesh with every hex positive.
    EXPECT_EQ(testing::check_known_mesh(g), "") << g.name;
    EXPECT_EQ(testing::count_positive_hexes(g.known_mesh), g.known_mesh.num_hexes()) << g.name;
    write_expected(dir, g);
    const Status s = write_hex_mesh(dir / (g.name + ext), g.known_mesh);
    EXPECT_TRUE(s.ok()) << g.name << ext << ": " << to_string(s);
    args += " " + g.name + ext;
  }
  return args;
}

/// Shared by both checks: expected data, the hex volume and the comparison of face sets.
constexpr const char* kPythonCommon = R"PY(
import collections, os, sys
import numpy as np
import meshio

d = sys.argv[1]
files = sys.argv[2:]

# Outward faces of a positive hex in VTK order, which is also C3D8's and HEX8's node order.
OUTWARD = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
# Abaqus C3D8 faces S1..S6 (manual: 1-2-3-4, 5-8-7-6, 1-5-6-2, 2-6-7-3, 3-7-8-4, 4-8-5-1).
C3D8_FACES = {1: (0, 1, 2, 3), 2: (4, 7, 6, 5), 3: (0, 4, 5, 1),
              4: (1, 5, 6, 2), 5: (2, 6, 7, 3), 6: (3, 7, 4, 0)}
# Exodus HEX8 sides 1..6 (manual: 1-2-6-5, 2-3-7-6, 3-4-8-7, 1-5-8-4, 1-4-3-2, 5-6-7-8).
HEX8_SIDES = {1: (0, 1, 5, 4), 2: (1, 2, 6, 5), 3: (2, 3, 7, 6),
              4: (0, 4, 7, 3), 5: (0, 3, 2, 1), 6: (4, 5, 6, 7)}

def expected(name):
    base = os.path.join(d, name)
    return (np.loadtxt(base + '.points.txt', ndmin=2),
            np.loadtxt(base + '.hexes.txt', dtype=np.int64, ndmin=2),
            np.loadtxt(base + '.quads.txt', dtype=np.int64, ndmin=2))

def volume(points, faces):
    """Volume enclosed by outward polygons, each fanned around its centroid."""
    v = 0.0
    for f in faces:
        q = points[list(f)]
        c = q.mean(axis=0)
        for k in range(len(f)):
            v += np.dot(c, np.cross(q[k], q[(k + 1) % len(f)]))
    return v / 6.0

def check_mesh(path, fmt, name):
    """Points, hexes and volumes as meshio reads them; returns (mesh, hexes, expected quads)."""
    pts, hexes, quads = expected(name)
    m = meshio.read(path, file_format=fmt)
    assert [c.type for c in m.cells] == ['hexahedron'], (path, [c.type for c in m.cells])
    read = np.asarray(m.cells[0].data, dtype=np.int64)
    assert m.points.shape == pts.shape, (path, m.points.shape, pts.shape)
    assert read.shape == hexes.shape, (path, read.shape, hexes.shape)
    assert np.array_equal(np.asarray(m.points, dtype=float), pts), path + ': coordinates differ'
    assert np.array_equal(read, hexes), path + ': hexes differ'
    vols = [volume(m.points, [[h[i] for i in f] for f in OUTWARD]) for h in read]
    assert min(vols) > 0, (path, 'non-positive hex volume', min(vols))
    enclosed = volume(m.points, quads)
    assert abs(sum(vols) - enclosed) <= 1e-9 * abs(enclosed), (path, sum(vols), enclosed)
    return m, read, quads

def check_boundary_nodes(path, nodes, quads):
    nodes = [int(v) for v in nodes]
    assert len(nodes) == len(set(nodes)), path + ': repeated boundary nodes'
    assert set(nodes) == set(int(v) for v in quads.flatten()), path + ': boundary nodes differ'

def check_faces(path, hexes, pairs, table, quads):
    """pairs: (0-based hex, face number); each boundary quad exactly once, nothing else."""
    got = collections.Counter(frozenset(int(hexes[e][i]) for i in table[s]) for e, s in pairs)
    want = collections.Counter(frozenset(int(v) for v in q) for q in quads)
    assert max(want.values()) == 1
    assert got == want, (path, 'faces differ', len(pairs), len(quads),
                         list((got - want).items())[:3], list((want - got).items())[:3])

def name_of(f):
    return os.path.splitext(f)[0]
)PY";

constexpr const char* kPythonAbaqus = R"PY(
for f in files:
    path = os.path.join(d, f)
    m, hexes, quads = check_mesh(path, 'abaqus', name_of(f))
    check_boundary_nodes(path, m.point_sets['BOUNDARY'], quads)
    lines = open(path).read().splitlines()
    assert lines[0] == '*HEADING', path
    assert '*ELEMENT, TYPE=C3D8, ELSET=HEXES' in lines, path
    assert len(m.cell_sets['HEXES'][0]) == len(hexes), path
    for line in lines:  # Abaqus data lines: at most 16 values, at most 256 characters
        if not line.startswith('*'):
            assert len(line.split(',')) <= 16 and len(line) <= 256, (path, line)
    start = lines.index('*SURFACE, NAME=BOUNDARY, TYPE=ELEMENT') + 1
    pairs = []
    for line in lines[start:]:
        if line.startswith('*'):
            break
        elset, face = [t.strip() for t in line.split(',')]
        assert face[0] == 'S', (path, line)
        for e in m.cell_sets[elset][0]:
            pairs.append((int(e), int(face[1:])))
    check_faces(path, hexes, pairs, C3D8_FACES, quads)
    print('ok', f, len(hexes), 'hexes', len(pairs), 'faces')
)PY";

constexpr const char* kPythonExodus = R"PY(
import netCDF4

def names(nc, var):
    return [str(s) for s in netCDF4.chartostring(nc.variables[var][:])]

for f in files:
    path = os.path.join(d, f)
    m, hexes, quads = check_mesh(path, 'exodus', name_of(f))
    check_boundary_nodes(path, m.point_sets['boundary'], quads)
    with netCDF4.Dataset(path) as nc:
        assert nc.variables['connect1'].elem_type == 'HEX8', path
        for c in ('coordx', 'coordy', 'coordz'):
            assert nc.variables[c].dtype == np.float64, (path, c)
        assert [int(v) for v in nc.variables['ns_prop1'][:]] == [1], path
        assert [int(v) for v in nc.variables['ss_prop1'][:]] == [1], path
        assert names(nc, 'ns_names') == ['boundary'], (path, names(nc, 'ns_names'))
        assert names(nc, 'ss_names') == ['boundary'], (path, names(nc, 'ss_names'))
        elems = [int(e) - 1 for e in nc.variables['elem_ss1'][:]]
        sides = [int(s) for s in nc.variables['side_ss1'][:]]
    check_faces(path, hexes, list(zip(elems, sides)), HEX8_SIDES, quads)
    print('ok', f, len(hexes), 'hexes', len(elems), 'sides')
)PY";

TEST(FeaFormats, MeshioReadsAbaqus) {
  if (!python_has("meshio")) GTEST_SKIP() << "/usr/bin/python3 cannot import meshio";
  const test_io::ScratchDir scratch_dir("fea_abaqus");
  const auto& dir = scratch_dir.path();
  const std::string args = write_cases(dir, ".inp");
  EXPECT_EQ(run_python(dir, "abaqus.py", std::string(kPythonCommon) + kPythonAbaqus, args), 0)
      << test_io::read_bytes(dir / "abaqus.py.log");
}

TEST(FeaFormats, MeshioAndNetcdfReadExodus) {
  if (!python_has("meshio, netCDF4")) GTEST_SKIP() << "/usr/bin/python3 cannot import netCDF4";
  const test_io::ScratchDir scratch_dir("fea_exodus");
  const auto& dir = scratch_dir.path();
  std::string args = write_cases(dir, ".exo");
  // .e is the same format; a case written under it is read the same way.
  const testing::Generated cube = testing::cube(2, 3, 4);
  ASSERT_TRUE(write_hex_mesh(dir / "cube234.e", cube.known_mesh).ok());
  args += " cube234.e";
  EXPECT_EQ(run_python(dir, "exodus.py", std::string(kPythonCommon) + kPythonExodus, args), 0)
      << test_io::read_bytes(dir / "exodus.py.log");
}

/// Two unit hexes stacked along z: the shared face z = 1 is not on the boundary.
HexMesh stacked_hexes() {
  HexMesh m;
  for (int k = 0; k < 3; ++k) {
    for (int v = 0; v < 4; ++v) m.points.emplace_back(v == 1 || v == 2 ? 1.0 : 0.0, v >= 2 ? 1.0 : 0.0, k);
  }
  m.hexes.push_back({0, 1, 2, 3, 4, 5, 6, 7});
  m.hexes.push_back({4, 5, 6, 7, 8, 9, 10, 11});
  return m;
}

TEST(FeaFormats, AbaqusDeckOfTwoHexes) {
  const test_io::ScratchDir scratch_dir("fea_two");
  const auto path = scratch_dir.path() / "two.inp";
  ASSERT_TRUE(write_hex_mesh(path, stacked_hexes()).ok());
  // Bottom (S1) of hex 1, top (S2) of hex 2, the four walls (S3-S6) of both.
  EXPECT_EQ(test_io::read_bytes(path),
            "*HEADING\nhexpeel hex mesh: 12 nodes, 2 C3D8 elements\n"
            "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 1, 1, 0\n4, 0, 1, 0\n"
            "5, 0, 0, 1\n6, 1, 0, 1\n7, 1, 1, 1\n8, 0, 1, 1\n"
            "9, 0, 0, 2\n10, 1, 0, 2\n11, 1, 1, 2\n12, 0, 1, 2\n"
            "*ELEMENT, TYPE=C3D8, ELSET=HEXES\n1, 1, 2, 3, 4, 5, 6, 7, 8\n2, 5, 6, 7, 8, 9, 10, 11, 12\n"
            "*NSET, NSET=BOUNDARY\n1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12\n"
            "*ELSET, ELSET=_BOUNDARY_S1\n1\n*ELSET, ELSET=_BOUNDARY_S2\n2\n"
            "*ELSET, ELSET=_BOUNDARY_S3\n1, 2\n*ELSET, ELSET=_BOUNDARY_S4\n1, 2\n"
            "*ELSET, ELSET=_BOUNDARY_S5\n1, 2\n*ELSET, ELSET=_BOUNDARY_S6\n1, 2\n"
            "*SURFACE, NAME=BOUNDARY, TYPE=ELEMENT\n_BOUNDARY_S1, S1\n_BOUNDARY_S2, S2\n"
            "_BOUNDARY_S3, S3\n_BOUNDARY_S4, S4\n_BOUNDARY_S5, S5\n_BOUNDARY_S6, S6\n");
}

TEST(FeaFormats, AbaqusSetLinesHoldAtMost16Values) {
  const test_io::ScratchDir scratch_dir("fea_lines");
  const auto path = scratch_dir.path() / "c.inp";
  const testing::Generated g = testing::cube(5, 5, 5);  // 152 boundary nodes, 25 faces per side
  ASSERT_TRUE(write_hex_mesh(path, g.known_mesh).ok());
  const std::string text = test_io::read_bytes(path);
  size_t longest = 0;
  for (size_t pos = 0; pos < text.size();) {
    const size_t end = text.find('\n', pos);
    const std::string line = text.substr(pos, end - pos);
    if (line.empty() || line[0] != '*') {
      size_t values = 1;
      for (char c : line) values += c == ',';
      longest = std::max(longest, values);
      EXPECT_LE(values, 16u) << line;
    }
    pos = end + 1;
  }
  EXPECT_EQ(longest, 16u);  // the sets do fill their lines
}

TEST(FeaFormats, WritesAreDeterministic) {
  const test_io::ScratchDir scratch_dir("fea_determinism");
  const auto& dir = scratch_dir.path();
  const testing::Generated g = testing::cubed_sphere(3);
  for (const char* name : {"s.inp", "s.exo", "S.E", "s.INP"}) {
    const auto path = dir / name;
    ASSERT_TRUE(is_hex_mesh_extension(path)) << name;
    ASSERT_TRUE(write_hex_mesh(path, g.known_mesh).ok()) << name;
    const std::string first = test_io::read_bytes(path);
    ASSERT_FALSE(first.empty()) << name;
    ASSERT_TRUE(write_hex_mesh(path, g.known_mesh).ok()) << name;  // over the existing file
    EXPECT_EQ(test_io::read_bytes(path), first) << name;
  }
  EXPECT_EQ(test_io::read_bytes(dir / "s.exo"), test_io::read_bytes(dir / "S.E"));
  EXPECT_EQ(test_io::read_bytes(dir / "s.inp"), test_io::read_bytes(dir / "s.INP"));
  HexMesh back;
  EXPECT_EQ(read_hex_mesh(dir / "s.exo", back).code, StatusCode::unsupported_format);
}

TEST(FeaFormats, FailedWritesLeaveNoFile) {
  const test_io::ScratchDir scratch_dir("fea_failed");
  const auto& dir = scratch_dir.path();
  const HexMesh mesh = stacked_hexes();
  for (const char* ext : {".inp", ".exo", ".e"}) {
    SCOPED_TRACE(ext);
    const auto missing = dir / "no_such_dir" / (std::string("m") + ext);
    const Status s = write_hex_mesh(missing, mesh);
    EXPECT_EQ(s.code, StatusCode::io_error);
    EXPECT_NE(s.message.find(missing.string()), std::string::npos) << s.message;
    EXPECT_FALSE(std::filesystem::exists(missing));

    // The target is a directory: the file is complete, the rename fails, the temporary goes.
    const auto taken = dir / (std::string("taken") + ext);
    std::filesystem::create_directories(taken);
    const Status t = write_hex_mesh(taken, mesh);
    EXPECT_EQ(t.code, StatusCode::io_error);
    EXPECT_NE(t.message.find(taken.string()), std::string::npos) << t.message;
    EXPECT_TRUE(std::filesystem::is_directory(taken));
    std::filesystem::remove(taken);
    EXPECT_TRUE(std::filesystem::is_empty(dir)) << "a temporary file was left behind";
  }
}

}  // namespace
}  // namespace hexpeel
