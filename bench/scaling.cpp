// hexpeel_scaling: time per stage and peak memory on cubed spheres with 6 n^2 quads, and the
// fitted growth exponent of each stage's time against the quad count (no pillowing or
// untangling: see hexpeel_untangle_bench). Prints figures only.
#include "bench_util.h"
#include "hexpeel/pipeline.h"
#include "support/generators.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <vector>

using namespace hexpeel;
namespace ht = hexpeel::testing;

int main(int argc, char** argv) {
  CLI::App app{"Scaling of the meshing stages on cubed spheres (6 n^2 quads)"};
  std::vector<int> ns{8, 16, 24, 32, 48, 64, 96, 128};
  app.add_option("--n", ns, "cubed sphere resolutions")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  const char* stages[] = {"check", "elimination", "reconstruction", "placement", "quality"};
  std::vector<double> quads;
  std::vector<std::vector<double>> times(5);
  std::printf("%6s %8s %8s %9s %9s %9s %9s %9s %9s %9s\n", "n", "quads", "hexes", "check_s",
              "elim_s", "recon_s", "place_s", "quality_s", "comb_s", "peak_MB");
  for (int n : ns) {
    bench::Isolated r = bench::run_isolated([n]() {
      ht::Generated g = ht::cubed_sphere_equiangular(n);
      PolygonSoup soup = to_polygon_soup(g.surface);
      // The combinatorial stages and the initial placement; untangling has its own benchmark
      // (hexpeel_untangle_bench scaling).
      MeshParams p;
      p.pillow.mode = PillowMode::none;
      p.untangle.untangle = false;
      p.untangle.optimize = false;
      MeshResult m = run_mesh(soup, p);
      nlohmann::json j = to_json(m);
      j["quads"] = g.surface.num_quads();
      return j;
    });
    const auto& j = r.result;
    if (!r.failure.empty() || j.value("status", "") != "ok") {
      std::printf("%6d failed: %s %s\n", n, r.failure.c_str(), j.value("message", "").c_str());
      continue;
    }
    quads.push_back(j["quads"].get<double>());
    double t[5];
    for (int s = 0; s < 5; ++s) times[s].push_back(t[s] = j["timings_s"][stages[s]].get<double>());
    std::printf("%6d %8d %8d %9.4f %9.4f %9.4f %9.4f %9.4f %9.4f %9.1f\n", n, j["quads"].get<int>(),
                j["hexes"].get<int>(), t[0], t[1], t[2], t[3], t[4], t[0] + t[1] + t[2],
                r.peak_rss_kb / 1024.0);
    std::fflush(stdout);
  }
  std::printf("fitted growth exponent of time vs quads:");
  for (int s = 0; s < 5; ++s) std::printf(" %s %.2f", stages[s], bench::fitted_exponent(quads, times[s]));
  std::printf("\n");
  return 0;
}
