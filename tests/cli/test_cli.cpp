// End-to-end tests of the hexpeel command line (apps/hexpeel/main.cpp): exit codes, messages on
// stderr, files written or not written, JSON report keys, determinism. The binary comes from the
// HEXPEEL_BIN environment variable (set by hexpeel_add_test); every fixture is generated here.
#include "support/generators.h"
#include "hexpeel/io.h"

#include "topology/soups.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <spawn.h>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

extern char** environ;

namespace {

namespace fs = std::filesystem;
namespace gen = hexpeel::testing;
using namespace hexpeel;

/// Outcome of one run of the binary.
struct Outcome {
  int exit_code = -1;   ///< exit status, -1 when the process did not exit normally
  int signal = 0;       ///< the signal that ended it, 0 when it exited
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

void spit(const fs::path& p, const std::string& bytes) {
  std::ofstream f(p, std::ios::binary);
  f << bytes;
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* bin = std::getenv("HEXPEEL_BIN");
    ASSERT_NE(bin, nullptr) << "HEXPEEL_BIN is not set";
    bin_ = bin;
    ASSERT_TRUE(fs::exists(bin_)) << bin_;
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("hexpeel_cli_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  /// Runs the binary with `args`, stdout and stderr captured, no shell involved.
  Outcome run(std::initializer_list<std::string> args) {
    return run(std::vector<std::string>(args));
  }
  Outcome run(const std::vector<std::string>& args) {
    std::vector<std::string> a{bin_};
    a.insert(a.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& s : a) argv.push_back(s.data());
    argv.push_back(nullptr);
    const fs::path out = dir_ / ".stdout", err = dir_ / ".stderr";
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&fa, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    pid_t pid = 0;
    Outcome r;
    const int rc = posix_spawn(&pid, bin_.c_str(), &fa, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&fa);
    EXPECT_EQ(rc, 0) << "cannot spawn " << bin_;
    if (rc != 0) return r;
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    if (WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
    if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
    r.out = slurp(out);
    r.err = slurp(err);
    fs::remove(out);
    fs::remove(err);
    return r;
  }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  /// `mesh in -o c.vtk` with each of `bad_args` is a usage error (exit 1) that writes nothing.
  void expect_usage_errors(const std::string& in,
                           const std::vector<std::vector<std::string>>& bad_args) {
    for (const std::vector<std::string>& bad_arg : bad_args) {
      std::vector<std::string> args{"mesh", in, "-o", path("c.vtk")};
      args.insert(args.end(), bad_arg.begin(), bad_arg.end());
      const Outcome bad = run(args);
      EXPECT_EQ(bad.exit_code, 1) << bad.err;
      EXPECT_FALSE(fs::exists(path("c.vtk")));
    }
  }
  /// `mesh in -o m.vtk --report m.json -q` with `extra`, expected to exit 0: the report.
  nlohmann::json mesh_report(const std::string& in, const std::vector<std::string>& extra) {
    std::vector<std::string> args{"mesh", in, "-o", path("m.vtk"), "--report", path("m.json"), "-q"};
    args.insert(args.end(), extra.begin(), extra.end());
    const Outcome o = run(args);
    EXPECT_EQ(o.exit_code, 0) << o.err;
    return nlohmann::json::parse(slurp(path("m.json")));
  }
  std::string write(const std::string& name, const std::string& bytes) {
    spit(dir_ / name, bytes);
    return path(name);
  }
  std::string write(const std::string& name, const QuadSurface& s) {
    const Status st = write_surface(dir_ / name, s);
    EXPECT_TRUE(st.ok()) << to_string(st);
    return path(name);
  }
  /// Files in the test directory (names), sorted.
  std::vector<std::string> listing() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

  std::string bin_;
  fs::path dir_;
};

/// A soup as OBJ text (1-based indices).
std::string obj_text(const PolygonSoup& soup) {
  std::ostringstream s;
  s.precision(17);
  for (const Vec3& p : soup.points) s << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  for (int32_t f = 0; f < soup.num_faces(); ++f) {
    s << 'f';
    for (int32_t i = soup.offsets[f]; i < soup.offsets[f + 1]; ++i) s << ' ' << soup.indices[i] + 1;
    s << '\n';
  }
  return s.str();
}

/// The soup with `other` appended (its vertex ids shifted), optionally with vertices of `other`
/// identified with vertices of `soup`: merge[i] = {other vertex, soup vertex}.
PolygonSoup join(PolygonSoup soup, const PolygonSoup& other,
                 const std::vector<std::pair<int32_t, int32_t>>& merge = {}) {
  std::vector<int32_t> id(other.points.size(), -1);
  for (auto [o, s] : merge) id[o] = s;
  for (size_t i = 0; i < other.points.size(); ++i)
    if (id[i] < 0) {
      id[i] = static_cast<int32_t>(soup.points.size());
      soup.points.push_back(other.points[i]);
    }
  for (int32_t f = 0; f < other.num_faces(); ++f) {
    for (int32_t i = other.offsets[f]; i < other.offsets[f + 1]; ++i)
      soup.indices.push_back(id[other.indices[i]]);
    soup.offsets.push_back(static_cast<int32_t>(soup.indices.size()));
  }
  return soup;
}

PolygonSoup translated(PolygonSoup soup, const Vec3& d) {
  for (Vec3& p : soup.points) p += d;
  return soup;
}

/// The id of the vertex at (x,y,z), -1 if none.
int32_t vertex_at(const PolygonSoup& soup, double x, double y, double z) {
  for (size_t i = 0; i < soup.points.size(); ++i)
    if (soup.points[i] == Vec3(x, y, z)) return static_cast<int32_t>(i);
  return -1;
}

bool contains(const std::string& haystack, const std::string& needle) {
  return haystack.find(needle) != std::string::npos;
}

#define EXPECT_NO_SIGNAL(r) EXPECT_EQ((r).signal, 0) << "killed by signal " << (r).signal << "\n" << (r).err

// ---- check --------------------------------------------------------------------------------------

TEST_F(Cli, CheckAcceptsValidSurface) {
  const std::string in = write("cube3.obj", gen::cube(3, 3, 3, 1.0 / 3).surface);
  Outcome r = run({"check", in, "--json", path("d.json")});
  EXPECT_NO_SIGNAL(r);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "verdict")) << r.out;
  EXPECT_TRUE(contains(r.out, "can be given to the mesher")) << r.out;
  // the text names the counts, the genus, the chords and the sharp edges
  EXPECT_TRUE(contains(r.out, "54")) << r.out;  // quads
  EXPECT_TRUE(contains(r.out, "genus")) << r.out;
  EXPECT_TRUE(contains(r.out, "chord")) << r.out;
  EXPECT_TRUE(contains(r.out, "sharp")) << r.out;
  EXPECT_TRUE(contains(r.out, "convex")) << r.out;
  EXPECT_TRUE(contains(r.out, "concave")) << r.out;
  ASSERT_TRUE(fs::exists(path("d.json")));
  const auto j = nlohmann::json::parse(slurp(path("d.json")));
  EXPECT_TRUE(j.at("status").at("ok").get<bool>());
  EXPECT_EQ(j.at("chords").at("count").get<int>(), 9);
}

TEST_F(Cli, CheckAcceptsCubedSphereAndVoxelSolid) {
  for (const auto& g : {gen::cubed_sphere_equiangular(4), gen::named_solid("L", 2)}) {
    const std::string in = write(g.name + ".off", g.surface);
    Outcome r = run({"check", in});
    EXPECT_NO_SIGNAL(r);
    EXPECT_EQ(r.exit_code, 0) << g.name << "\n" << r.out << r.err;
  }
}

/// One bad input: file name, contents, and words the message must contain (any of each group).
struct Bad {
  std::string name;
  std::string bytes;
  std::vector<std::string> words;  ///< each must appear in stderr (case-sensitive)
};

std::vector<Bad> bad_inputs() {
  using test::cube_soup;
  std::vector<Bad> v;
  const PolygonSoup cube = cube_soup();
  // non-quad face: the first quad split into two triangles
  {
    PolygonSoup s;
    s.points = cube.points;
    const int32_t* q = &cube.indices[0];
    s.add_face({q[0], q[1], q[2]});
    s.add_face({q[0], q[2], q[3]});
    for (int32_t f = 1; f < cube.num_faces(); ++f)
      s.add_face({cube.indices[4 * f], cube.indices[4 * f + 1], cube.indices[4 * f + 2],
                  cube.indices[4 * f + 3]});
    v.push_back({"nonquad.obj", obj_text(s), {"non_quad", "face"}});
  }
  // open boundary: two opposite faces of the cube removed (4 quads, an open tube)
  {
    PolygonSoup s;
    s.points = cube.points;
    for (int32_t f = 2; f < cube.num_faces(); ++f)
      s.add_face({cube.indices[4 * f], cube.indices[4 * f + 1], cube.indices[4 * f + 2],
                  cube.indices[4 * f + 3]});
    v.push_back({"open.obj", obj_text(s), {"open_boundary", "edge"}});
  }
  // non-manifold edge: two cubes sharing one edge
  {
    const PolygonSoup other = translated(cube, Vec3(1, 1, 0));
    const PolygonSoup s = join(cube, other,
                               {{vertex_at(other, 1, 1, 0), vertex_at(cube, 1, 1, 0)},
                                {vertex_at(other, 1, 1, 1), vertex_at(cube, 1, 1, 1)}});
    v.push_back({"nm_edge.obj", obj_text(s), {"non_manifold_edge", "edge"}});
  }
  // non-manifold vertex: two cubes sharing one corner
  {
    const PolygonSoup other = translated(cube, Vec3(1, 1, 1));
    const PolygonSoup s = join(cube, other, {{vertex_at(other, 1, 1, 1), vertex_at(cube, 1, 1, 1)}});
    v.push_back({"nm_vertex.obj", obj_text(s), {"non_manifold_vertex", "vertex"}});
  }
  v.push_back({"klein.obj", obj_text(test::klein_soup(6, 4)),
               {"inconsistent_orientation", "not orientable"}});
  v.push_back({"two.obj", obj_text(join(cube, translated(cube, Vec3(3, 0, 0)))),
               {"multiple_components", "component"}});
  v.push_back({"torus.obj", obj_text(test::torus_soup(8, 4)), {"nonzero_genus", "genus 1"}});
  v.push_back({"odd.obj", obj_text(test::prism_radial_soup()), {"odd_quad_count", "9"}});
  // a valid closed genus-0 surface (8 quads) whose one chord crosses itself
  v.push_back({"selfint.obj",
               obj_text(test::radial_soup({{1, 1, 0}, {-1, 1, 0}, {-1, -1, 0}, {1, -1, 0}, {0, 0, 1}},
                                          {{0, 3, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}})),
               {"self_intersecting_chord", "crosses itself"}});
  // degenerate quad: a quad with a repeated corner
  {
    PolygonSoup s = cube;
    s.add_face({0, 1, 1, 2});
    v.push_back({"degenerate.obj", obj_text(s), {"degenerate", "quad"}});
  }
  // duplicate vertex: a second copy of a corner, used by one of its quads
  {
    PolygonSoup s = cube;
    s.points.push_back(s.points[s.indices[0]]);
    s.indices[0] = static_cast<int32_t>(s.points.size()) - 1;
    v.push_back({"dupvert.obj", obj_text(s), {"duplicate_vertex", "vertex"}});
  }
  {
    std::string t = obj_text(cube);
    t.replace(t.find("v 0 0 0"), 7, "v nan 0 0");
    v.push_back({"nan.obj", t, {"non_finite", "NaN"}});
  }
  {
    std::string t = obj_text(cube);
    t += "f 1 2 3 99\n";
    v.push_back({"range.obj", t, {"index_out_of_range", "99"}});
  }
  {
    std::string t = obj_text(cube);
    t += "f 1 2 3 -99\n";  // relative index before the first vertex
    v.push_back({"relrange.obj", t, {"index_out_of_range", "-99"}});
  }
  v.push_back({"empty.obj", "", {"empty"}});
  v.push_back({"trunc.off", "OFF\n8 6 0\n0 0 0\n1 0 0\n1 1 0\n0 1", {"trunc.off"}});
  {
    std::string ply = "ply\nformat binary_little_endian 1.0\nelement vertex 8\nproperty float x\n"
                      "property float y\nproperty float z\nelement face 6\n"
                      "property list uchar int vertex_indices\nend_header\n";
    ply += std::string(40, '\0');  // 40 of the 96 vertex bytes, no faces
    v.push_back({"trunc.ply", ply, {"trunc.ply"}});
  }
  v.push_back({"surface.stl", "solid x\nendsolid x\n", {".stl"}});
  return v;
}

TEST_F(Cli, CheckRejectsEveryBadInputClass) {
  for (const Bad& b : bad_inputs()) {
    SCOPED_TRACE(b.name);
    const std::string in = write(b.name, b.bytes);
    Outcome r = run({"check", in});
    EXPECT_NO_SIGNAL(r);
    EXPECT_NE(r.exit_code, 0) << r.out << r.err;
    EXPECT_EQ(r.exit_code, 2) << r.err;
    for (const std::string& w : b.words) EXPECT_TRUE(contains(r.err, w)) << "'" << w << "' not in:\n" << r.err;
    EXPECT_FALSE(contains(r.out, "verdict: " + in + " can be given")) << r.out;
  }
}

TEST_F(Cli, CheckFlipsInwardSurfaceWithWarning) {
  PolygonSoup cube = test::cube_soup();
  for (int32_t f = 0; f < cube.num_faces(); ++f) cube = test::with_face_reversed(cube, f);
  const std::string in = write("inward.obj", obj_text(cube));
  Outcome r = run({"check", in});
  EXPECT_NO_SIGNAL(r);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(r.err, "warning")) << r.err;
  EXPECT_TRUE(contains(r.err, "inward")) << r.err;
}

TEST_F(Cli, MixedOrientationIsReorientedAndMeshesTheSame) {
  // One patch of quads (a CAD face, say) written the other way round, each from the same first
  // corner: reversed back with a warning that counts them, and then the very mesh of the
  // consistent surface.
  const QuadSurface s = gen::cubed_sphere_equiangular(3).surface;
  PolygonSoup mixed = to_polygon_soup(s);
  int32_t reversed = 0;
  for (int32_t q = 0; q < s.num_quads(); ++q) {
    Vec3 c = Vec3::Zero();
    for (int32_t v : s.quads[q]) c += s.points[v];
    if (c.x() > 2.0) {
      std::swap(mixed.indices[mixed.offsets[q] + 1], mixed.indices[mixed.offsets[q] + 3]);
      ++reversed;
    }
  }
  ASSERT_GT(reversed, 0);
  ASSERT_LT(2 * reversed, s.num_quads());
  const std::string good = write("good.obj", s), bad = write("mixed.obj", obj_text(mixed));
  Outcome c = run({"check", bad});
  EXPECT_EQ(c.exit_code, 0) << c.err;
  EXPECT_TRUE(contains(c.err, std::to_string(reversed) + " quads were reversed")) << c.err;
  Outcome a = run({"mesh", good, "-o", path("good.vtk"), "--quiet"});
  Outcome b = run({"mesh", bad, "-o", path("mixed.vtk"), "--quiet", "--report", path("r.json")});
  ASSERT_EQ(a.exit_code, 0) << a.err;
  ASSERT_EQ(b.exit_code, 0) << b.err;
  EXPECT_TRUE(contains(b.err, "reversed to agree")) << b.err;
  EXPECT_TRUE(slurp(path("good.vtk")) == slurp(path("mixed.vtk")));
  const auto report = nlohmann::json::parse(slurp(path("r.json")));
  EXPECT_EQ(report["input"]["validation"]["reoriented"].size(), static_cast<size_t>(reversed))
      << report.dump().substr(0, 400);
}

TEST_F(Cli, CheckTellsThePathAndCountsSelfCrossings) {
  const std::string good = write("sphere.obj", gen::cubed_sphere_equiangular(2).surface);
  Outcome g = run({"check", good, "--json", path("g.json")});
  EXPECT_EQ(g.exit_code, 0) << g.err;
  EXPECT_TRUE(contains(g.out, "path: dual cycle elimination")) << g.out;
  // 8 quads, one chord through all of them, crossing itself at each quad it passes twice
  const std::string bad = write(
      "selfint.obj",
      obj_text(test::radial_soup({{1, 1, 0}, {-1, 1, 0}, {-1, -1, 0}, {1, -1, 0}, {0, 0, 1}},
                                 {{0, 3, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}})));
  Outcome b = run({"check", bad, "--json", path("b.json")});
  EXPECT_EQ(b.exit_code, 2) << b.err;
  const auto j = nlohmann::json::parse(slurp(path("b.json")));
  const int crossings = j["chords"]["self_crossings"];
  int listed = 0;
  for (const auto& c : j["chords"]["self_intersecting"]) listed += static_cast<int>(c["crossings"].size());
  EXPECT_GT(crossings, 0);
  EXPECT_EQ(crossings, listed);
  EXPECT_TRUE(contains(b.out, "path: none: 1 of 1 chords cross themselves, at " +
                                  std::to_string(crossings) + " quads"))
      << b.out;
  EXPECT_TRUE(contains(j["path"].get<std::string>(), "not implemented")) << j.dump();
  EXPECT_TRUE(contains(nlohmann::json::parse(slurp(path("g.json")))["path"].get<std::string>(),
                       "dual cycle elimination"));
}

TEST_F(Cli, CheckReportsUnreadableFiles) {
  Outcome missing = run({"check", path("missing.obj")});
  EXPECT_NO_SIGNAL(missing);
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_TRUE(contains(missing.err, "missing.obj")) << missing.err;
  fs::create_directories(dir_ / "folder.obj");
  Outcome folder = run({"check", path("folder.obj")});
  EXPECT_NO_SIGNAL(folder);
  EXPECT_EQ(folder.exit_code, 2);
  EXPECT_TRUE(contains(folder.err, "folder.obj")) << folder.err;
  EXPECT_TRUE(contains(folder.err, "directory")) << folder.err;
}

// A hex mesh given as the surface: without faces an error naming its hexahedra, writing
// nothing; with its boundary quads beside them, a warning and the quads are meshed.
TEST_F(Cli, HexMeshGivenAsSurface) {
  const std::string in = write("cube2.obj", gen::cube(2, 2, 2, 0.5).surface);
  ASSERT_EQ(run({"mesh", in, "-o", path("m.vtk"), "-q"}).exit_code, 0);
  const Outcome volume = run({"mesh", path("m.vtk"), "-o", path("n.vtk"), "-q"});
  EXPECT_NO_SIGNAL(volume);
  EXPECT_NE(volume.exit_code, 0);
  EXPECT_TRUE(contains(volume.err, "8 hexahedra and no surface faces")) << volume.err;
  EXPECT_FALSE(fs::exists(path("n.vtk")));

  HexMesh mesh;
  ASSERT_TRUE(read_hex_mesh(path("m.vtk"), mesh).ok());
  const QuadSurface cube = gen::cube(2, 2, 2, 0.5).surface;
  std::string v = "# vtk DataFile Version 4.2\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS " +
                  std::to_string(mesh.points.size()) + " double\n";
  for (const Vec3& p : mesh.points) v += std::to_string(p.x()) + " " + std::to_string(p.y()) + " " + std::to_string(p.z()) + "\n";
  const size_t cells = mesh.hexes.size() + cube.quads.size();
  v += "CELLS " + std::to_string(cells) + " " + std::to_string(9 * mesh.hexes.size() + 5 * cube.quads.size()) + "\n";
  for (const Hex& h : mesh.hexes) {
    v += "8";
    for (int32_t c : h) v += " " + std::to_string(c);
    v += "\n";
  }
  // hexpeel keeps the input's vertices first, in their order: the cube's quads index them as is
  for (const Quad& q : cube.quads) v += "4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) + " " + std::to_string(q[3]) + "\n";
  v += "CELL_TYPES " + std::to_string(cells) + "\n";
  for (size_t c = 0; c < cells; ++c) v += c < mesh.hexes.size() ? "12\n" : "9\n";
  spit(path("both.vtk"), v);
  const Outcome both = run({"mesh", path("both.vtk"), "-o", path("b.vtk"), "-q"});
  EXPECT_NO_SIGNAL(both);
  EXPECT_EQ(both.exit_code, 0) << both.err;
  EXPECT_TRUE(contains(both.err, "8 hexahedra ignored")) << both.err;
  EXPECT_TRUE(fs::exists(path("b.vtk")));
}

TEST_F(Cli, CheckNeverCrashesOnDamagedBytes) {
  const std::string good = obj_text(test::grid_soup(2));
  uint32_t x = 12345;
  for (int round = 0; round < 20; ++round) {
    std::string bytes = good;
    for (int k = 0; k < 3; ++k) {
      x = x * 1664525u + 1013904223u;
      bytes[x % bytes.size()] = static_cast<char>(x >> 24);
    }
    const std::string in = write("damaged.obj", bytes);
    Outcome r = run({"check", in});
    EXPECT_NO_SIGNAL(r);
    EXPECT_TRUE(r.exit_code == 0 || r.exit_code == 2) << "round " << round << " exit " << r.exit_code << "\n" << r.err;
  }
}

// ---- mesh ---------------------------------------------------------------------------------------

TEST_F(Cli, MeshWritesMeshAndReport) {
  const std::string in = write("cube2.obj", gen::cube(2, 2, 2, 0.5).surface);
  Outcome r = run({"mesh", in, "-o", path("out.vtk"), "--report", path("report.json"), "--quiet"});
  EXPECT_NO_SIGNAL(r);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(fs::exists(path("out.vtk")));
  HexMesh mesh;
  ASSERT_TRUE(read_hex_mesh(path("out.vtk"), mesh).ok());
  const auto j = nlohmann::json::parse(slurp(path("report.json")));
  EXPECT_EQ(j.at("hexes").get<int>(), mesh.num_hexes());
  for (const char* k : {"min", "mean", "max", "count_nonpositive"}) EXPECT_TRUE(j.at("scaled_jacobian").contains(k)) << k;
  for (const char* k : {"interior", "boundary"}) EXPECT_TRUE(j.at("singular_edges").contains(k)) << k;
  EXPECT_EQ(j.at("euler_characteristic").get<int>(), 1);
  EXPECT_TRUE(j.at("boundary_matches_surface").get<bool>());
  EXPECT_TRUE(j.contains("chords"));
  EXPECT_TRUE(j.contains("steps"));
  EXPECT_EQ(j.at("status").get<std::string>(), "ok");
  for (const char* k : {"read", "check", "elimination", "reconstruction", "placement", "write"})
    EXPECT_TRUE(j.at("timings_s").contains(k)) << k;
  EXPECT_EQ(listing(), (std::vector<std::string>{"cube2.obj", "out.vtk", "report.json"}));
  // One order was tried, and it is the one the report names.
  ASSERT_EQ(j.at("orders_tried").size(), 1u);
  EXPECT_TRUE(j.at("orders_tried")[0].at("kept").get<bool>());
  EXPECT_EQ(j.at("orders_tried")[0].at("method"), j.at("method").at("name"));
  EXPECT_EQ(j.at("orders_tried")[0].at("side_rule"), j.at("method").at("side_rule"));
}

// --no-mean-sweep: the sweep over every interior vertex is skipped (other bytes, a lower mean);
// --alternatives is range-checked.
TEST_F(Cli, MeanSweepCanBeSkipped) {
  const std::string in =
      write("rvox.obj", gen::pillowed(gen::random_voxel_solid(3, 4, 12, 2), 3, 0.3).surface);
  Outcome a = run({"mesh", in, "-o", path("a.vtk"), "--report", path("a.json"), "--quiet"});
  Outcome b = run({"mesh", in, "-o", path("b.vtk"), "--report", path("b.json"), "--quiet",
                   "--no-mean-sweep"});
  ASSERT_EQ(a.exit_code, 0) << a.err;
  ASSERT_EQ(b.exit_code, 0) << b.err;
  const auto ja = nlohmann::json::parse(slurp(path("a.json")));
  const auto jb = nlohmann::json::parse(slurp(path("b.json")));
  // The sweep over every vertex is for the mean (the moves alone do not tell: without it the
  // worst hexes' vertices can take more steps).
  EXPECT_GT(ja.at("scaled_jacobian").at("mean").get<double>(),
            jb.at("scaled_jacobian").at("mean").get<double>());
  EXPECT_GT(ja.at("untangle").at("local_moves").get<int64_t>(), 0);
  EXPECT_NE(slurp(path("a.vtk")), slurp(path("b.vtk")));
  expect_usage_errors(in, {{"--alternatives", "4"}});
}

// --quality-passes: the report counts the passes; one pass gives a lower minimum on this solid,
// whose second pass raises it (0.4965 -> 0.4998); the count is range-checked.
TEST_F(Cli, QualityPassesOption) {
  const std::string in =
      write("rvox.obj", gen::pillowed(gen::random_voxel_solid(1, 4, 12, 2), 1, 0.3).surface);
  Outcome a = run({"mesh", in, "-o", path("a.vtk"), "--report", path("a.json"), "--quiet"});
  Outcome b = run({"mesh", in, "-o", path("b.vtk"), "--report", path("b.json"), "--quiet",
                   "--quality-passes", "1"});
  ASSERT_EQ(a.exit_code, 0) << a.err;
  ASSERT_EQ(b.exit_code, 0) << b.err;
  const auto ja = nlohmann::json::parse(slurp(path("a.json")));
  const auto jb = nlohmann::json::parse(slurp(path("b.json")));
  EXPECT_GE(ja.at("untangle").at("quality_passes").get<int>(), 2);
  EXPECT_EQ(jb.at("untangle").at("quality_passes").get<int>(), 1);
  EXPECT_GT(ja.at("scaled_jacobian").at("min").get<double>(),
            jb.at("scaled_jacobian").at("min").get<double>() + 1e-3);
  expect_usage_errors(in, {{"--quality-passes", "0"}});
}

// --final-polish-runs: the report counts the runs and whether the polish stayed; 0 skips it and
// gives a lower mean on this solid (0.7393 -> 0.7282); the count is range-checked.
TEST_F(Cli, FinalPolishRunsOption) {
  const std::string in =
      write("rvox.obj", gen::pillowed(gen::random_voxel_solid(10, 4, 12, 2), 10, 0.3).surface);
  Outcome a = run({"mesh", in, "-o", path("a.vtk"), "--report", path("a.json"), "--quiet"});
  Outcome b = run({"mesh", in, "-o", path("b.vtk"), "--report", path("b.json"), "--quiet",
                   "--final-polish-runs", "0"});
  ASSERT_EQ(a.exit_code, 0) << a.err;
  ASSERT_EQ(b.exit_code, 0) << b.err;
  const auto ja = nlohmann::json::parse(slurp(path("a.json")));
  const auto jb = nlohmann::json::parse(slurp(path("b.json")));
  EXPECT_GE(ja.at("untangle").at("final_polish_runs").get<int>(), 1);
  EXPECT_TRUE(ja.at("untangle").at("final_polish_kept").get<bool>());
  EXPECT_EQ(jb.at("untangle").at("final_polish_runs").get<int>(), 0);
  EXPECT_FALSE(jb.at("untangle").at("final_polish_kept").get<bool>());
  EXPECT_GT(ja.at("scaled_jacobian").at("mean").get<double>(),
            jb.at("scaled_jacobian").at("mean").get<double>() + 0.005);
  expect_usage_errors(in, {{"--final-polish-runs", "101"}});
}

// --pillow-whole-fraction and --pillow-grow: this solid's 4 forced corners grow into a local set
// large enough that auto pillows the whole boundary (226 new hexes); with the fraction at 1 the
// pillow stays local, and one ring of growth pillows fewer hexes than two; both are range-checked.
TEST_F(Cli, PillowShrinkSetOptions) {
  const std::string in =
      write("rvox.obj", gen::pillowed(gen::random_voxel_solid(10, 4, 12, 2), 10, 0.3).surface);
  auto pillow_of = [&](std::vector<std::string> extra) {
    std::vector<std::string> args{"mesh", in, "-o", path("a.vtk"), "--report", path("a.json"),
                                  "--quiet", "--alternatives", "0", "--no-untangle"};
    args.insert(args.end(), extra.begin(), extra.end());
    Outcome o = run(args);
    EXPECT_NE(o.exit_code, 1) << o.err;  // a mesh with hexes <= 0 exits 5: fine here
    return nlohmann::json::parse(slurp(path("a.json"))).at("pillow");
  };
  const auto whole = pillow_of({});
  const auto local2 = pillow_of({"--pillow-whole-fraction", "1"});
  const auto local1 = pillow_of({"--pillow-whole-fraction", "1", "--pillow-grow", "1"});
  EXPECT_TRUE(whole.at("whole_boundary").get<bool>());
  EXPECT_FALSE(local2.at("whole_boundary").get<bool>());
  EXPECT_FALSE(local1.at("whole_boundary").get<bool>());
  EXPECT_LT(local2.at("new_hexes").get<int>(), whole.at("new_hexes").get<int>());
  EXPECT_LT(local1.at("new_hexes").get<int>(), local2.at("new_hexes").get<int>());
  expect_usage_errors(
      in, {{"--pillow-grow", "11"}, {"--pillow-whole-fraction", "1.5"}, {"--pillow-margin", "-0.1"}});
}

// The stuck fill's options: the 20-quad surface no chord can leave is filled by default, fails
// as stuck (exit 3, nothing written) when the fill may not take surfaces that large, and the
// options are range-checked.
TEST_F(Cli, StuckFillOptions) {
  const std::string in = write("stuck.obj", gen::stuck_surface());
  const Outcome filled = run({"mesh", in, "-o", path("f.vtk"), "--report", path("f.json"), "-q"});
  EXPECT_EQ(filled.exit_code, 0) << filled.err;
  const auto fill = nlohmann::json::parse(slurp(path("f.json"))).at("stuck_fill");
  EXPECT_TRUE(fill.at("filled").get<bool>());
  EXPECT_EQ(fill.at("stuck_quads").get<int>(), 20);
  const Outcome small = run({"mesh", in, "-o", path("s.vtk"), "--stuck-fill-quads", "19", "-q"});
  EXPECT_EQ(small.exit_code, 3) << small.err;
  EXPECT_NE(small.err.find("stuck"), std::string::npos) << small.err;
  EXPECT_FALSE(fs::exists(path("s.vtk")));
  expect_usage_errors(in, {{"--stuck-fill-quads", "0"}, {"--stuck-fill-budget", "0"}});
}

// --pillow-retry-band: the report's pillow_retry on a coarse cubed sphere whose minimum is a
// corner fixed by the boundary (the retry pillows it: 64 -> 160 hexes), 0 turns it off, and the
// band is range-checked.
TEST_F(Cli, PillowRetryBandOption) {
  const std::string in = write("cs4.obj", gen::cubed_sphere_equiangular(4).surface);
  auto report = [&](const std::vector<std::string>& extra) { return mesh_report(in, extra); };
  const nlohmann::json on = report({}), off = report({"--pillow-retry-band", "0"});
  EXPECT_TRUE(on.at("pillow_retry").at("tried").get<bool>());
  EXPECT_TRUE(on.at("pillow_retry").at("kept").get<bool>());
  EXPECT_EQ(on.at("pillow_retry").at("first").at("hexes").get<int>(), off.at("hexes").get<int>());
  EXPECT_EQ(on.at("pillow_retry").at("retry").at("hexes").get<int>(), on.at("hexes").get<int>());
  EXPECT_GT(on.at("timings_s").at("pillow_retry").get<double>(), 0.0);
  EXPECT_FALSE(off.at("pillow_retry").at("tried").get<bool>());
  EXPECT_GT(on.at("scaled_jacobian").at("min").get<double>(),
            off.at("scaled_jacobian").at("min").get<double>() + 0.3);
  EXPECT_FALSE(on.at("pillow_repair").at("tried").get<bool>());  // every hex positive at once
  expect_usage_errors(
      in, {{"--pillow-retry-band", "1.5"}, {"--repair-rounds", "-1"}, {"--repair-rounds", "21"}});
}

// --no-intrusion-cover: this random voxel solid's plan refuses intrusions; the plan rebuilt with
// covering steps intrudes them all and is meshed too, but the refused steps extruded give the
// ideal cubes, so that mesh is kept (as it is without the cover). With --strict-intrusion the
// rebuilt plan's mesh is the only one, and kept.
TEST_F(Cli, IntrusionCoverOption) {
  const std::string in = write("rvox.obj", gen::random_voxel_solid(374, 6, 28, 1).surface);
  auto report = [&](const std::vector<std::string>& extra) { return mesh_report(in, extra); };
  const nlohmann::json on = report({}),
                       off = report({"--no-intrusion-cover", "--intrusion-flip-rounds", "0"});
  ASSERT_TRUE(on.contains("intrusion_cover")) << on.dump();
  const nlohmann::json& c = on.at("intrusion_cover");
  EXPECT_GT(c.at("refused_before").get<int>(), 0);
  EXPECT_EQ(c.at("refused_after").get<int>(), 0);
  EXPECT_GE(c.at("cover_steps").get<int>(), 1);
  EXPECT_FALSE(c.at("kept").get<bool>());
  EXPECT_GT(on.at("timings_s").at("intrusion_cover").get<double>(), 0.0);
  EXPECT_FALSE(off.contains("intrusion_cover"));
  EXPECT_EQ(off.at("timings_s").at("intrusion_cover").get<double>(), 0.0);
  EXPECT_EQ(on.at("hexes").get<int>(), off.at("hexes").get<int>());
  EXPECT_EQ(on.at("scaled_jacobian").at("min").get<double>(), 1.0);
  EXPECT_EQ(on.at("reconstruction").at("invalid_intrusion_steps"),
            off.at("reconstruction").at("invalid_intrusion_steps"));
  // The flip (--intrusion-flip-rounds) turns the refused step to its other side: every
  // intrusion goes, but the refused step extruded gave the ideal cubes, which stay.
  const nlohmann::json& f = on.at("intrusion_cover").at("flip");
  EXPECT_TRUE(f.at("tried").get<bool>());
  EXPECT_FALSE(f.at("kept").get<bool>());
  EXPECT_EQ(f.at("refused_before").get<int>(), c.at("refused_before").get<int>());
  EXPECT_EQ(f.at("refused_after").get<int>(), 0);
  EXPECT_GE(f.at("flipped_steps").get<int>(), 1);
  const nlohmann::json flip_only = report({"--no-intrusion-cover"});
  EXPECT_FALSE(flip_only.at("intrusion_cover").at("tried").get<bool>());
  EXPECT_TRUE(flip_only.at("intrusion_cover").at("flip").at("tried").get<bool>());
  EXPECT_EQ(flip_only.at("hexes").get<int>(), off.at("hexes").get<int>());
  // --strict-intrusion stops the first reconstruction at its first refusal; the rebuilt plan,
  // which intrudes every concave step, is then the only mesh, and it is kept.
  const nlohmann::json strict = report({"--strict-intrusion"});
  const nlohmann::json& sc = strict.at("intrusion_cover");
  EXPECT_TRUE(sc.at("kept").get<bool>());
  EXPECT_EQ(sc.at("refused_before").get<int>(), 1);
  EXPECT_EQ(sc.at("refused_after").get<int>(), 0);
  EXPECT_TRUE(strict.at("reconstruction").at("invalid_intrusion_steps").empty());
  EXPECT_GT(strict.at("reconstruction").at("intrusions").get<int>(), 0);
  EXPECT_EQ(strict.at("status").get<std::string>(), "ok");
}

// --regularization: a weaker size term in the passes raises this solid's minimum (measured:
// 0.4736 -> 0.4841 with 0.003); the weight is range-checked.
TEST_F(Cli, RegularizationOption) {
  const std::string in =
      write("rvox.obj", gen::pillowed(gen::random_voxel_solid(7, 4, 12, 2), 7, 0.3).surface);
  auto min_sj = [&](const std::string& weight) {
    const Outcome o = run({"mesh", in, "-o", path("m.vtk"), "--report", path("m.json"), "-q",
                           "--regularization", weight});
    EXPECT_EQ(o.exit_code, 0) << o.err;
    return nlohmann::json::parse(slurp(path("m.json"))).at("scaled_jacobian").at("min").get<double>();
  };
  EXPECT_GT(min_sj("0.003"), min_sj("0.01") + 0.005);
  expect_usage_errors(in, {{"--regularization", "1.5"}});
}

// A pillowed voxel solid whose reconstruction has hexes lying flat in the boundary (all 8
// corners on it): without a pillow no placement helps, so the mesh is written and exit code 5
// says it is not fit for a solver.
TEST_F(Cli, MeshWithInvertedHexesExitsFive) {
  const std::string in =
      write("rvox.obj", gen::pillowed(gen::random_voxel_solid(1, 4, 12, 2), 1, 0.3).surface);
  Outcome r = run({"mesh", in, "-o", path("out.vtk"), "--pillow", "none", "--quiet"});
  EXPECT_NO_SIGNAL(r);
  EXPECT_EQ(r.exit_code, 5) << r.out << r.err;
  EXPECT_TRUE(contains(r.err, "scaled Jacobian <= 0")) << r.err;
  ASSERT_TRUE(fs::exists(path("out.vtk")));
  HexMesh mesh;
  ASSERT_TRUE(read_hex_mesh(path("out.vtk"), mesh).ok());
  EXPECT_GT(mesh.num_hexes(), 0);
  // The default pillow serves it: exit 0.
  Outcome ok = run({"mesh", in, "-o", path("ok.vtk"), "--quiet"});
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
}

TEST_F(Cli, EffortPresets) {
  const std::string in = write("sphere.obj", gen::cubed_sphere_equiangular(3).surface);
  Outcome plain = run({"mesh", in, "-o", path("plain.vtk"), "--quiet", "--report", path("plain.json")});
  Outcome def = run({"mesh", in, "-o", path("default.vtk"), "--quiet", "--effort", "default"});
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  ASSERT_EQ(def.exit_code, 0) << def.err;
  EXPECT_TRUE(slurp(path("plain.vtk")) == slurp(path("default.vtk")));  // default changes nothing
  const auto p = nlohmann::json::parse(slurp(path("plain.json")))["params"];
  EXPECT_EQ(p["plan_budget_s"], 30.0);
  EXPECT_EQ(p["alternatives"], 3);
  // fast: its preset, except what is given explicitly
  Outcome fast = run({"mesh", in, "-o", path("fast.vtk"), "--quiet", "--effort", "fast",
                      "--alternatives", "2", "--report", path("fast.json")});
  ASSERT_EQ(fast.exit_code, 0) << fast.err;
  const auto f = nlohmann::json::parse(slurp(path("fast.json")));
  EXPECT_EQ(f["params"]["final_polish_runs"], 1);
  EXPECT_EQ(f["params"]["quality_passes"], 1);
  EXPECT_EQ(f["params"]["alternatives"], 2);
  EXPECT_EQ(f["scaled_jacobian"]["count_nonpositive"], 0);
  Outcome best = run({"mesh", in, "-o", path("best.vtk"), "--quiet", "--effort", "best",
                      "--report", path("best.json")});
  ASSERT_EQ(best.exit_code, 0) << best.err;
  const auto b = nlohmann::json::parse(slurp(path("best.json")));
  EXPECT_EQ(b["params"]["alternatives_always"], true);
  EXPECT_EQ(b["params"]["quality_passes"], 5);
  EXPECT_GE(b["scaled_jacobian"]["min"].get<double>(), f["scaled_jacobian"]["min"].get<double>() - 1e-9);
  Outcome bad = run({"mesh", in, "-o", path("x.vtk"), "--effort", "extreme"});
  EXPECT_EQ(bad.exit_code, 1) << bad.err;
  // the everyday help is short; --help-all lists the expert options too
  Outcome help = run({"mesh", "--help"});
  Outcome all = run({"mesh", "--help-all"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_FALSE(contains(help.out, "--final-polish-softmin")) << help.out;
  EXPECT_TRUE(contains(help.out, "--effort")) << help.out;
  EXPECT_TRUE(contains(all.out, "--final-polish-softmin")) << all.out;
  EXPECT_LE(std::count(help.out.begin(), help.out.end(), '\n'), 40);
}

TEST_F(Cli, MeshIsDeterministic) {
  const std::string in = write("sphere.obj", gen::cubed_sphere_equiangular(3).surface);
  for (const char* ext : {".vtk", ".vtu", ".mesh", ".msh"}) {
    Outcome a = run({"mesh", in, "-o", path(std::string("a") + ext), "--quiet"});
    Outcome b = run({"mesh", in, "-o", path(std::string("b") + ext), "--quiet"});
    ASSERT_EQ(a.exit_code, 0) << a.err;
    ASSERT_EQ(b.exit_code, 0) << b.err;
    const std::string fa = slurp(path(std::string("a") + ext)), fb = slurp(path(std::string("b") + ext));
    EXPECT_FALSE(fa.empty());
    EXPECT_TRUE(fa == fb) << ext;
  }
}

TEST_F(Cli, ThreadCountDoesNotChangeTheOutput) {
  // Big enough (about 2k hexes) for the parallel loops to split the work.
  const std::string in = write("sphere.obj", gen::cubed_sphere_equiangular(6).surface);
  Outcome a = run({"mesh", in, "-o", path("a.vtk"), "--report", path("a.json"), "--quiet"});
  Outcome b = run({"mesh", in, "-o", path("b.vtk"), "--report", path("b.json"), "--quiet",
                   "--threads", "1"});
  Outcome c = run({"mesh", in, "-o", path("c.vtk"), "--quiet", "--threads", "3"});
  ASSERT_EQ(a.exit_code, 0) << a.err;
  ASSERT_EQ(b.exit_code, 0) << b.err;
  ASSERT_EQ(c.exit_code, 0) << c.err;
  EXPECT_FALSE(slurp(path("a.vtk")).empty());
  EXPECT_TRUE(slurp(path("a.vtk")) == slurp(path("b.vtk")));
  EXPECT_TRUE(slurp(path("a.vtk")) == slurp(path("c.vtk")));
  const auto ja = nlohmann::json::parse(slurp(path("a.json")));
  const auto jb = nlohmann::json::parse(slurp(path("b.json")));
  EXPECT_EQ(ja.at("scaled_jacobian"), jb.at("scaled_jacobian"));
  Outcome qa = run({"quality", path("a.vtk"), "--json", path("qa.json")});
  Outcome qb = run({"quality", path("a.vtk"), "--json", path("qb.json"), "--threads", "1"});
  EXPECT_EQ(qa.exit_code, 0) << qa.err;
  EXPECT_EQ(qb.exit_code, 0) << qb.err;
  EXPECT_EQ(slurp(path("qa.json")), slurp(path("qb.json")));
  for (const char* n : {"-1", "1025"}) {
    Outcome bad = run({"mesh", in, "-o", path("d.vtk"), "--threads", n});
    EXPECT_EQ(bad.exit_code, 1) << n << bad.err;
    EXPECT_TRUE(contains(bad.err, "--threads")) << n << bad.err;
    EXPECT_FALSE(fs::exists(path("d.vtk")));
  }
}

TEST_F(Cli, SelfIntersectingSurfaceIsRefusedByCheckAndMesh) {
  // The 3x3x3 block's boundary with an inner top vertex pushed down through the bottom face.
  PolygonSoup s = test::grid_soup(3);
  for (Vec3& p : s.points)
    if (p == Vec3(1, 1, 3)) p.z() = -0.5;
  const std::string in = write("pushed.obj", obj_text(s));
  Outcome c = run({"check", in});
  EXPECT_NO_SIGNAL(c);
  EXPECT_EQ(c.exit_code, 2) << c.err;
  EXPECT_TRUE(contains(c.err, "self_intersecting_surface")) << c.err;
  EXPECT_TRUE(contains(c.err, "intersects itself")) << c.err;
  Outcome m = run({"mesh", in, "-o", path("out.vtk")});
  EXPECT_NO_SIGNAL(m);
  EXPECT_EQ(m.exit_code, 2) << m.err;
  EXPECT_TRUE(contains(m.err, "intersects itself")) << m.err;
  EXPECT_EQ(listing(), std::vector<std::string>{"pushed.obj"});
}

TEST_F(Cli, FailedMeshLeavesNoFileBehind) {
  // bad input
  const std::string bad = write("torus.obj", obj_text(test::torus_soup(8, 4)));
  Outcome r = run({"mesh", bad, "-o", path("out.vtk")});
  EXPECT_NO_SIGNAL(r);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_TRUE(contains(r.err, "genus")) << r.err;
  EXPECT_EQ(listing(), std::vector<std::string>{"torus.obj"});
  // unwritable output: the output's directory is a regular file
  const std::string in = write("cube.obj", gen::cube(1, 1, 1).surface);
  r = run({"mesh", in, "-o", path("torus.obj") + "/out.vtk", "--report", path("r.json")});
  EXPECT_NO_SIGNAL(r);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_TRUE(contains(r.err, "out.vtk")) << r.err;
  // the report of the failed run says why
  EXPECT_EQ(nlohmann::json::parse(slurp(path("r.json"))).at("status").get<std::string>(), "io_error");
  fs::remove(path("r.json"));
  r = run({"mesh", in, "-o", path("nowhere") + "/out.vtk"});
  EXPECT_NO_SIGNAL(r);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(listing(), (std::vector<std::string>{"cube.obj", "torus.obj"}));
}

TEST_F(Cli, RepairSurfaceMeshesRefusedSurfacesAndWritesTheBoundary) {
  const std::string in = write("odd.obj", obj_text(test::prism_radial_soup()));
  // refused without the option, and the message names it
  Outcome r = run({"mesh", in, "-o", path("out.vtk")});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_TRUE(contains(r.err, "--repair-surface")) << r.err;
  // check tells what the repair would do
  r = run({"check", in});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_TRUE(contains(r.out, "with --repair-surface: split into six, 54 quads")) << r.out;
  // --repaired-surface alone is a usage error, before anything is read or written
  r = run({"mesh", in, "-o", path("out.vtk"), "--repaired-surface", path("rep.obj")});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_TRUE(contains(r.err, "needs --repair-surface")) << r.err;
  EXPECT_EQ(listing(), std::vector<std::string>{"odd.obj"});
  // with it: the mesh, the repaired surface and a report that says what changed
  r = run({"mesh", in, "-o", path("out.vtk"), "--repair-surface", "--repaired-surface",
           path("rep.obj"), "--report", path("r.json")});
  EXPECT_NO_SIGNAL(r);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(r.err, "surface repaired")) << r.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(path("r.json")));
  EXPECT_EQ(j.at("repair").at("input_quads"), 9);
  EXPECT_EQ(j.at("repair").at("input_odd"), true);
  EXPECT_EQ(j.at("repair").at("quads_changed"), 9);
  // the mesh's boundary is the repaired surface, exactly
  r = run({"quality", path("out.vtk"), "--surface", path("rep.obj")});
  EXPECT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_TRUE(contains(r.out, "topological ball: yes")) << r.out;
  EXPECT_TRUE(contains(r.out, "hexes with SJ <= 0: 0")) << r.out;
  EXPECT_TRUE(contains(r.out, "boundary equals surface: yes")) << r.out;
  r = run({"check", path("rep.obj")});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
}

TEST_F(Cli, PatchSetsNameTheSidesOfABox) {
  const std::string in = write("cube3.obj", gen::cube(3, 3, 3, 1.0 / 3).surface);
  // a format without boundary groups: a usage error naming the option, nothing written
  Outcome r = run({"mesh", in, "-o", path("out.vtk"), "--patch-sets"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_TRUE(contains(r.err, "--patch-sets")) << r.err;
  EXPECT_EQ(listing(), std::vector<std::string>{"cube3.obj"});
  r = run({"mesh", in, "-o", path("out.inp"), "--patch-sets"});
  EXPECT_NO_SIGNAL(r);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "boundary patches: 6")) << r.out;
  const std::string deck = slurp(path("out.inp"));
  EXPECT_TRUE(contains(deck, "*SURFACE, NAME=BOUNDARY, TYPE=ELEMENT")) << deck.substr(0, 200);
  EXPECT_TRUE(contains(deck, "*SURFACE, NAME=PATCH_6, TYPE=ELEMENT"));
  EXPECT_FALSE(contains(deck, "PATCH_7"));
  // every quad of one side in one patch: 9 faces each, over the six patches' element sets
  r = run({"mesh", in, "-o", path("plain.inp")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(contains(slurp(path("plain.inp")), "PATCH_"));
}

TEST_F(Cli, HtmlReportLoadsInHeadlessChromium) {
  const std::string in = write("L.obj", gen::named_solid("L", 2).surface);
  Outcome r = run({"mesh", in, "-o", path("m.vtk"), "--html", path("m.html"), "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string page = slurp(path("m.html"));
  // self-contained: nothing fetched from anywhere
  EXPECT_FALSE(contains(page, "http://"));
  EXPECT_FALSE(contains(page, "https://"));
  EXPECT_FALSE(contains(page, " src=")) << "an external script or image";
  EXPECT_TRUE(contains(page, "<svg class=\"hist\""));
  EXPECT_TRUE(contains(page, "<h1>L.obj</h1>"));
  // hexpeel quality writes the same report of the written mesh
  r = run({"quality", path("m.vtk"), "--html", path("q.html")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(slurp(path("q.html")), "<h1>m.vtk</h1>"));
  // a failed run writes no report
  r = run({"mesh", write("odd.obj", obj_text(test::prism_radial_soup())), "-o", path("x.vtk"),
           "--html", path("x.html"), "-q"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(fs::exists(path("x.html")));

  if (std::system("command -v chromium > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "chromium is not installed (Debian: apt-get install chromium)";
  const std::string flags = "--headless --no-sandbox --use-gl=angle --use-angle=swiftshader "
                            "--enable-unsafe-swiftshader --enable-logging=stderr --v=0 "
                            "--window-size=900,1500 --virtual-time-budget=10000 --user-data-dir='" +
                            path("profile") + "' ";
  // Chromium must work here at all (a page with no script); a machine where it cannot start is
  // a skip, not a failure of the report.
  spit(path("plain.html"), "<html><body><p id=\"p\">plain</p></body></html>");
  if (std::system(("timeout 120 chromium " + flags + "--dump-dom 'file://" + path("plain.html") +
                   "' > '" + path("plain.txt") + "' 2> /dev/null").c_str()) != 0 ||
      !contains(slurp(path("plain.txt")), "id=\"p\">plain"))
    GTEST_SKIP() << "chromium does not run on this machine";
  const std::string url = "'file://" + path("m.html") + "'";
  ASSERT_EQ(std::system(("timeout 120 chromium " + flags + "--dump-dom " + url + " > '" +
                         path("dom.txt") + "' 2> '" + path("chromium.log") + "'").c_str()), 0)
      << slurp(path("chromium.log"));
  const std::string dom = slurp(path("dom.txt"));
  const size_t div = dom.find("id=\"status\"");
  ASSERT_NE(div, std::string::npos);
  const size_t at = dom.find("viewer-ready: ", div);
  ASSERT_TRUE(at != std::string::npos && at < dom.find('<', div)) << dom.substr(div, 200);
  // "viewer-ready: F faces drawn of H hexes, P pixels": the view covers a good part of the canvas
  const std::string line = dom.substr(at, dom.find('<', at) - at);
  const long pixels = std::atol(line.substr(line.rfind(", ") + 2).c_str());
  EXPECT_GT(pixels, 20000) << line;
  EXPECT_FALSE(contains(slurp(path("chromium.log")), "INFO:CONSOLE")) << slurp(path("chromium.log"));
  // and the screenshot is not blank: many non-white pixels in the view's part of the page
  ASSERT_EQ(std::system(("timeout 120 chromium " + flags + "--screenshot='" + path("m.png") +
                         "' " + url + " > /dev/null 2>&1").c_str()), 0);
  ASSERT_TRUE(fs::exists(path("m.png")));
  if (std::system("/usr/bin/python3 -c 'import vtk' > /dev/null 2>&1") != 0) return;
  spit(path("png.py"),
       "import sys, vtk\n"
       "from vtk.util.numpy_support import vtk_to_numpy\n"
       "r = vtk.vtkPNGReader(); r.SetFileName(sys.argv[1]); r.Update()\n"
       "img = r.GetOutput(); w, h, _ = img.GetDimensions()\n"
       "a = vtk_to_numpy(img.GetPointData().GetScalars()).reshape(h, w, -1)[:, :, :3]\n"
       "lower = a[: h // 2]  # VTK rows run bottom up: the lower half of the page holds the view\n"
       "colored = ((lower.max(axis=2).astype(int) - lower.min(axis=2)) > 40).sum()\n"
       "print(colored); sys.exit(0 if colored > 20000 else 1)\n");
  EXPECT_EQ(std::system(("/usr/bin/python3 '" + path("png.py") + "' '" + path("m.png") + "' > '" +
                         path("png.log") + "' 2>&1").c_str()), 0)
      << slurp(path("png.log"));
}

TEST_F(Cli, MeshRejectsUnknownOutputExtensionFirst) {
  // the input does not even exist: the output extension is reported before any reading
  Outcome r = run({"mesh", path("missing.obj"), "-o", path("out.stl")});
  EXPECT_NO_SIGNAL(r);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_TRUE(contains(r.err, "out.stl")) << r.err;
  EXPECT_FALSE(contains(r.err, "missing.obj")) << r.err;
  EXPECT_TRUE(listing().empty());
}

// ---- quality ------------------------------------------------------------------------------------

TEST_F(Cli, QualityOfGoodMeshAndSurfaceMismatch) {
  const gen::Generated g = gen::cube(2, 2, 2, 0.5);
  const std::string surf = write("cube2.obj", g.surface);
  ASSERT_TRUE(write_hex_mesh(path("grid.vtu"), g.known_mesh).ok());
  Outcome r = run({"quality", path("grid.vtu"), "--surface", surf, "--json", path("q.json")});
  EXPECT_NO_SIGNAL(r);
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  const auto j = nlohmann::json::parse(slurp(path("q.json")));
  EXPECT_EQ(j.at("hexes").get<int>(), 8);
  EXPECT_NEAR(j.at("scaled_jacobian").at("min").get<double>(), 1.0, 1e-12);
  EXPECT_NEAR(j.at("scaled_jacobian").at("mean").get<double>(), 1.0, 1e-12);
  EXPECT_NEAR(j.at("scaled_jacobian").at("max").get<double>(), 1.0, 1e-12);
  EXPECT_EQ(j.at("scaled_jacobian").at("count_nonpositive").get<int>(), 0);
  EXPECT_EQ(j.at("singular_edges").at("interior").get<int>(), 0);
  // boundary edges along the 12 cube edges (2 segments each) have one hex, not two
  EXPECT_EQ(j.at("singular_edges").at("boundary").get<int>(), 24);
  EXPECT_EQ(j.at("euler_characteristic").get<int>(), 1);
  EXPECT_TRUE(j.at("boundary_matches_surface").get<bool>());

  const std::string other = write("cube3.obj", gen::cube(3, 3, 3, 1.0 / 3).surface);
  r = run({"quality", path("grid.vtu"), "--surface", other, "--json", path("q2.json")});
  EXPECT_NO_SIGNAL(r);
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_TRUE(contains(r.err, "boundary differs from " + other)) << r.err;
  const auto j2 = nlohmann::json::parse(slurp(path("q2.json")));
  EXPECT_FALSE(j2.at("boundary_matches_surface").get<bool>());
}

TEST_F(Cli, QualityRejectsBadMeshFiles) {
  Outcome r = run({"quality", path("missing.vtk")});
  EXPECT_NO_SIGNAL(r);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.err, "missing.vtk")) << r.err;
  r = run({"quality", write("junk.msh", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 8 1")});
  EXPECT_NO_SIGNAL(r);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  r = run({"quality", write("mesh.xyz", "1 2 3\n")});
  EXPECT_NO_SIGNAL(r);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_TRUE(contains(r.err, ".xyz")) << r.err;
}

// ---- usage --------------------------------------------------------------------------------------

TEST_F(Cli, UsageErrorsExitOneWithUsage) {
  for (const auto& args : std::vector<std::vector<std::string>>{
           {}, {"check"}, {"mesh", "in.obj"}, {"quality"}, {"frobnicate"}, {"check", "a.obj", "--bogus"}}) {
    std::string joined;
    for (const auto& a : args) joined += a + " ";
    SCOPED_TRACE(joined);
    Outcome r;
    switch (args.size()) {
      case 0: r = run({}); break;
      case 1: r = run({args[0]}); break;
      case 2: r = run({args[0], args[1]}); break;
      default: r = run({args[0], args[1], args[2]}); break;
    }
    EXPECT_NO_SIGNAL(r);
    EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
    EXPECT_TRUE(contains(r.out + r.err, "Usage")) << r.out << r.err;
  }
  Outcome help = run({"--help"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_TRUE(contains(help.out, "check")) << help.out;
}

}  // namespace
