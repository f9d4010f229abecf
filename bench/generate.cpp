// hexpeel_generate: writes generated test surfaces (OBJ) into a folder, for the corpus runner and
// for examples. Every surface is the boundary of a known hex mesh; its hex count goes into
// reference.tsv (name, hexes, min SJ, mean SJ of the known mesh; SJ left empty when unknown).
#include "hexpeel/io.h"
#include "hexpeel/quality.h"
#include "support/generators.h"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

using namespace hexpeel;
namespace ht = hexpeel::testing;

int main(int argc, char** argv) {
  CLI::App app{"Write generated quad surfaces (OBJ) and a reference.tsv of their known hex meshes"};
  std::string outdir;
  std::string family = "all";
  app.add_option("OUTDIR", outdir, "folder to write into (created)")->required();
  app.add_option("--family", family, "all | cubes | spheres | named | random | pillowed | perturbed")
      ->capture_default_str();
  std::vector<int> sphere_n{4, 8, 12};
  app.add_option("--sphere-n", sphere_n, "resolutions n of the cubed spheres (6 n^2 quads)")
      ->check(CLI::Range(1, 512));
  CLI11_PARSE(app, argc, argv);
  std::filesystem::create_directories(outdir);

  std::vector<ht::Generated> out;
  auto want = [&](const char* f) { return family == "all" || family == f; };
  if (want("cubes"))
    for (int n : {2, 4, 8}) out.push_back(ht::cube(n, n, n, 1.0 / n));
  if (want("spheres"))
    for (int n : sphere_n) out.push_back(ht::cubed_sphere_equiangular(n));
  if (want("named"))
    for (const char* s : {"L", "Lblock", "U", "T", "pocket", "notch", "stairs", "steps"})
      for (int m = 1; m <= 3; ++m) out.push_back(ht::named_solid(s, m));
  if (want("random"))
    for (uint64_t seed = 1; seed <= 10; ++seed)
      out.push_back(ht::random_voxel_solid(seed, 5, 10 + 3 * static_cast<int>(seed), 1 + seed % 2));
  if (want("pillowed"))
    for (uint64_t seed = 1; seed <= 10; ++seed)
      out.push_back(ht::pillowed(ht::random_voxel_solid(seed, 4, 12, 2), seed, 0.3));
  if (want("perturbed"))
    for (uint64_t seed = 1; seed <= 5; ++seed)
      out.push_back(ht::jittered(ht::random_voxel_solid(50 + seed, 4, 10, 2), seed, 0.15));

  std::string tsv = "name\treference_hexes\treference_min_sj\treference_mean_sj\n";
  int written = 0;
  for (const auto& g : out) {
    if (g.surface.num_quads() == 0) continue;
    Status st = write_surface(std::filesystem::path(outdir) / (g.name + ".obj"), g.surface);
    if (!st.ok()) {
      std::fprintf(stderr, "hexpeel_generate: %s\n", to_string(st).c_str());
      return 2;
    }
    ++written;
    tsv += g.name + "\t" + std::to_string(g.known_mesh.num_hexes());
    if (g.known_mesh.num_hexes() > 0) {
      QualityReport q = run_quality(g.known_mesh);
      char buf[64];
      std::snprintf(buf, sizeof buf, "\t%.4f\t%.4f\n", q.sj_min, q.sj_mean);
      tsv += buf;
    } else {
      tsv += "\t\t\n";
    }
  }
  Status st = write_text_file(std::filesystem::path(outdir) / "reference.tsv", tsv);
  if (!st.ok()) {
    std::fprintf(stderr, "hexpeel_generate: %s\n", to_string(st).c_str());
    return 2;
  }
  std::printf("wrote %d surfaces and reference.tsv to %s\n", written, outdir.c_str());
  return 0;
}
