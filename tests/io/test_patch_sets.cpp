// Boundary patches (write_hex_mesh with BoundaryPatches, `hexpeel mesh --patch-sets`): the surface
// cut along its sharp edges, and one named boundary group per patch in Exodus II, Abaqus, Gmsh and
// MEDIT, read back by readers independent of ours (netCDF4, plain text, meshio). The expected
// patches of a box are its six sides, found from the quad normals, not from sharp_patches.
#include "hexpeel/chords.h"
#include "hexpeel/io.h"
#include "io_fixtures.h"
#include "support/generators.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace hexpeel {
namespace {

std::vector<int32_t> patches_of(const QuadSurface& s, int32_t& count) {
  const QuadAdjacency adj = build_adjacency(s);
  return sharp_patches(s, adj, classify_edges(s, adj, 60.0), count);
}

BoundaryPatches boundary_patches_of(const testing::Generated& g) {
  BoundaryPatches p;
  p.faces = g.surface.quads;
  p.patch = patches_of(g.surface, p.count);
  return p;
}

TEST(PatchSets, BoxPatchesAreItsSides) {
  const testing::Generated g = testing::cube(2, 3, 4);
  int32_t count = 0;
  const std::vector<int32_t> patch = patches_of(g.surface, count);
  ASSERT_EQ(count, 6);
  // Two quads share a patch exactly when their outward normals point the same way.
  std::map<int32_t, std::set<std::string>> normals_of;
  for (int32_t q = 0; q < g.surface.num_quads(); ++q) {
    const Vec3 n = quad_normal(g.surface, q);
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (std::abs(n[k]) > std::abs(n[axis])) axis = k;
    normals_of[patch[q]].insert(std::to_string(axis) + (n[axis] > 0 ? "+" : "-"));
  }
  std::set<std::string> all;
  for (const auto& [p, dirs] : normals_of) {
    EXPECT_EQ(dirs.size(), 1u) << "patch " << p;
    all.insert(dirs.begin(), dirs.end());
  }
  EXPECT_EQ(all.size(), 6u);
  // Numbered by smallest quad: patch ids first appear in increasing order.
  int32_t next = 0;
  for (const int32_t p : patch) {
    ASSERT_LE(p, next);
    if (p == next) ++next;
  }
}

TEST(PatchSets, SmoothSurfaceIsOnePatch) {
  int32_t count = 0;
  patches_of(testing::cubed_sphere_equiangular(8).surface, count);
  EXPECT_EQ(count, 1);
}

constexpr const char* kPythonPatches = R"PY(
import collections, os, sys
import numpy as np

d, name = sys.argv[1], sys.argv[2]
quads = np.loadtxt(os.path.join(d, name + '.quads.txt'), dtype=np.int64, ndmin=2)
patch = np.loadtxt(os.path.join(d, name + '.patch.txt'), dtype=np.int64, ndmin=1)
hexes = np.loadtxt(os.path.join(d, name + '.hexes.txt'), dtype=np.int64, ndmin=2)
want = {}
for q, p in zip(quads, patch):
    want.setdefault(int(p) + 1, collections.Counter())[frozenset(int(v) for v in q)] += 1

C3D8_FACES = {1: (0, 1, 2, 3), 2: (4, 7, 6, 5), 3: (0, 4, 5, 1),
              4: (1, 5, 6, 2), 5: (2, 6, 7, 3), 6: (3, 7, 4, 0)}
HEX8_SIDES = {1: (0, 1, 5, 4), 2: (1, 2, 6, 5), 3: (2, 3, 7, 6),
              4: (0, 4, 7, 3), 5: (0, 3, 2, 1), 6: (4, 5, 6, 7)}

def faces(pairs, table):
    return collections.Counter(frozenset(int(hexes[e][i]) for i in table[s]) for e, s in pairs)

def same(fmt, got):
    assert got == want, (fmt, sorted(got), sorted(want),
                         {k: len(v) for k, v in got.items()}, {k: len(v) for k, v in want.items()})
    print('ok', fmt, len(got), 'patches')

# Abaqus: element-based surfaces PATCH_k over element sets, by plain text.
lines = open(os.path.join(d, name + '.inp')).read().splitlines()
elsets, cur = {}, None
for line in lines:
    if line.startswith('*ELSET, ELSET='):
        cur = line.split('=')[1]
        elsets[cur] = []
    elif line.startswith('*'):
        cur = None
    elif cur is not None:
        elsets[cur] += [int(t) - 1 for t in line.split(',')]
got = {}
for i, line in enumerate(lines):
    if line.startswith('*SURFACE, NAME=PATCH_'):
        k = int(line.split('NAME=PATCH_')[1].split(',')[0])
        pairs = []
        for l in lines[i + 1:]:
            if l.startswith('*'):
                break
            elset, face = [t.strip() for t in l.split(',')]
            pairs += [(e, int(face[1:])) for e in elsets[elset]]
        got[k] = faces(pairs, C3D8_FACES)
same('inp', got)

# Exodus II: side sets 2.. named patch_k, by netCDF4.
import netCDF4
with netCDF4.Dataset(os.path.join(d, name + '.exo')) as nc:
    names = [str(s) for s in netCDF4.chartostring(nc.variables['ss_names'][:])]
    ids = [int(v) for v in nc.variables['ss_prop1'][:]]
    got = {}
    for j, (n, i) in enumerate(zip(names, ids)):
        if n == 'boundary':
            assert i == 1, (n, i)
            continue
        assert n == 'patch_%d' % (i - 1), (n, i)
        elems = [int(e) - 1 for e in nc.variables['elem_ss%d' % (j + 1)][:]]
        sides = [int(s) for s in nc.variables['side_ss%d' % (j + 1)][:]]
        got[i - 1] = faces(zip(elems, sides), HEX8_SIDES)
same('exo', got)

import meshio
# Gmsh: quads in physical groups named patch_k.
m = meshio.read(os.path.join(d, name + '.msh'))
tag_name = {int(v[0]): k for k, v in m.field_data.items() if int(v[1]) == 2}
got = {}
for block, tags in zip(m.cells, m.cell_data['gmsh:physical']):
    if block.type != 'quad':
        continue
    for q, t in zip(block.data, tags):
        k = int(tag_name[int(t)].split('_')[1])
        got.setdefault(k, collections.Counter())[frozenset(int(v) for v in q)] += 1
same('msh', got)
assert [c.type for c in m.cells].count('hexahedron') == 1
assert sum(len(c.data) for c in m.cells if c.type == 'hexahedron') == len(hexes)

# MEDIT: quadrilaterals whose reference is k.
m = meshio.read(os.path.join(d, name + '.mesh'))
got = {}
for block, refs in zip(m.cells, m.cell_data['medit:ref']):
    if block.type != 'quad':
        continue
    for q, r in zip(block.data, refs):
        got.setdefault(int(r), collections.Counter())[frozenset(int(v) for v in q)] += 1
same('mesh', got)
)PY";

TEST(PatchSets, EveryFormatCarriesThePatches) {
  const std::string probe = "/usr/bin/python3 -c 'import meshio, netCDF4' > /dev/null 2>&1";
  if (std::system(probe.c_str()) != 0) GTEST_SKIP() << "/usr/bin/python3 lacks meshio or netCDF4";
  const test_io::ScratchDir scratch_dir("patch_sets");
  const auto& dir = scratch_dir.path();
  std::vector<testing::Generated> cases{testing::cube(2, 3, 4), testing::named_solid("L", 2)};
  cases[0].name = "box";
  cases[1].name = "lsolid";
  for (const testing::Generated& g : cases) {
    SCOPED_TRACE(g.name);
    ASSERT_EQ(testing::check_known_mesh(g), "");
    const BoundaryPatches p = boundary_patches_of(g);
    ASSERT_GE(p.count, 6);
    std::string quads, patch, hexes;
    for (size_t i = 0; i < p.faces.size(); ++i) {
      for (int k = 0; k < 4; ++k) quads += std::to_string(p.faces[i][k]) + (k < 3 ? " " : "\n");
      patch += std::to_string(p.patch[i]) + "\n";
    }
    for (const Hex& h : g.known_mesh.hexes)
      for (int k = 0; k < 8; ++k) hexes += std::to_string(h[k]) + (k < 7 ? " " : "\n");
    test_io::write_bytes(dir / (g.name + ".quads.txt"), quads);
    test_io::write_bytes(dir / (g.name + ".patch.txt"), patch);
    test_io::write_bytes(dir / (g.name + ".hexes.txt"), hexes);
    for (const char* ext : {".inp", ".exo", ".msh", ".mesh"}) {
      const Status s = write_hex_mesh(dir / (g.name + ext), g.known_mesh, &p);
      ASSERT_TRUE(s.ok()) << ext << ": " << to_string(s);
    }
    test_io::write_bytes(dir / "patches.py", kPythonPatches);
    const std::string cmd = "/usr/bin/python3 '" + (dir / "patches.py").string() + "' '" +
                            dir.string() + "' " + g.name + " > '" + (dir / "log").string() + "' 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << test_io::read_bytes(dir / "log");
  }
}

TEST(PatchSets, WithoutPatchesTheFilesAreAsBefore) {
  const test_io::ScratchDir scratch_dir("patch_sets_none");
  const auto& dir = scratch_dir.path();
  const testing::Generated g = testing::cube(2, 2, 2);
  BoundaryPatches empty;  // no faces, no patches: the formats get nothing more
  for (const char* ext : {".inp", ".msh", ".mesh"}) {
    ASSERT_TRUE(write_hex_mesh(dir / (std::string("a") + ext), g.known_mesh).ok());
    ASSERT_TRUE(write_hex_mesh(dir / (std::string("b") + ext), g.known_mesh, &empty).ok());
  }
  EXPECT_EQ(test_io::read_bytes(dir / "a.inp"), test_io::read_bytes(dir / "b.inp"));
  EXPECT_EQ(test_io::read_bytes(dir / "a.msh").find("$PhysicalNames"), std::string::npos);
  EXPECT_EQ(test_io::read_bytes(dir / "a.mesh").find("Quadrilaterals"), std::string::npos);
  EXPECT_NE(test_io::read_bytes(dir / "b.mesh").find("Quadrilaterals\n0\n"), std::string::npos);
}

TEST(PatchSets, FaceNotOnTheBoundaryIsAnErrorAndNothingIsWritten) {
  const test_io::ScratchDir scratch_dir("patch_sets_bad");
  const auto& dir = scratch_dir.path();
  const testing::Generated g = testing::cube(2, 2, 2);
  BoundaryPatches p = boundary_patches_of(g);
  // The face between the two bottom-front hexes (x = 0.5) is interior.
  const Hex& h = g.known_mesh.hexes[0];
  p.faces.push_back({h[1], h[2], h[6], h[5]});
  p.patch.push_back(0);
  for (const char* ext : {".inp", ".exo", ".msh", ".mesh"}) {
    const auto path = dir / (std::string("m") + ext);
    const Status s = write_hex_mesh(path, g.known_mesh, &p);
    EXPECT_EQ(s.code, StatusCode::invalid_mesh) << ext;
    EXPECT_NE(s.message.find("is not a boundary face"), std::string::npos) << s.message;
    EXPECT_NE(s.message.find(path.string()), std::string::npos) << s.message;
    EXPECT_FALSE(std::filesystem::exists(path)) << ext;
  }
  BoundaryPatches q = boundary_patches_of(g);
  q.patch[3] = q.count;  // out of range
  EXPECT_EQ(write_hex_mesh(dir / "q.inp", g.known_mesh, &q).code, StatusCode::invalid_mesh);
  q = boundary_patches_of(g);
  q.faces.push_back(q.faces.front());  // twice
  q.patch.push_back(0);
  EXPECT_EQ(write_hex_mesh(dir / "r.inp", g.known_mesh, &q).code, StatusCode::invalid_mesh);
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

}  // namespace
}  // namespace hexpeel
