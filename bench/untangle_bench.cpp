// Untangling / optimization / pillowing figures: a markdown table per run, never an assertion.
//
//   hexpeel_untangle_bench mesh FILE... [--pillow auto|all|none] [--greedy] [--family]
//                                       [--solver newton|lbfgs] [--simplicial]
//       full pipeline on each surface file (and with --family on generated surfaces): hexes,
//       forced configurations, min/mean SJ after placement and after each phase, times.
//   hexpeel_untangle_bench scaling [--sizes 10,22,46] [--threads N] [--solver newton|lbfgs]
//                                  [--simplicial] [--no-mean-sweep] [--final-polish-runs N]
//       the optimizer alone on jittered equiangular cubed spheres of n^3 hexes: time per phase,
//       the mean scaled Jacobian at the end,
//       iterations / evaluations (Newton: also factorizations and the time spent assembling,
//       factorizing and solving), corner-evaluations per second (one corner term with its
//       gradient; phase 2 evaluates only its focus region, so evaluations differ in size).
//   Run both --solver values to compare L-BFGS and Newton on the same machine.
#include "hexpeel/pipeline.h"
#include "hexpeel/io.h"
#include "hexpeel/untangle.h"
#include "support/generators.h"

#include <CLI/CLI.hpp>
#include <tbb/global_control.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace {

using namespace hexpeel;

void mesh_row(const std::string& name, const PolygonSoup& soup, const MeshParams& given) {
  MeshParams base = given;
  base.alternatives = 0;  // one order: the row compares its placement with its untangling
  MeshParams p0 = base;
  p0.untangle.untangle = p0.untangle.optimize = false;
  MeshResult r0 = run_mesh(soup, p0);
  if (!r0.status.ok()) {
    std::printf("| %s | %s | | | | | | | |\n", name.c_str(), std::string(to_string(r0.status.code)).c_str());
    return;
  }
  const auto t = std::chrono::steady_clock::now();
  MeshResult r = run_mesh(soup, base);
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  const UntangleStats& u = r.untangle;
  std::printf("| %s | %d | %d (%dd/%dc/%df) | %d+%d%s | %.3f / %.3f (%d<=0) | %.3f (%d<=0) | "
              "%.3f / %.3f (%d<=0) | %d/%d | %.2f+%.2f s | %.2f s |\n",
              name.c_str(), r.quality.hexes, r.pillow.forced, r.pillow.flat_doublets,
              r.pillow.concave_corners, r.pillow.fixed_corners, r.pillow.shrink_set,
              r.pillow.new_hexes, r.pillow.whole_boundary ? " whole" : "", r0.quality.sj_min,
              r0.quality.sj_mean, r0.quality.sj_count_nonpositive, u.untangle.min_sj_after,
              u.untangle.nonpositive_after, r.quality.sj_min, r.quality.sj_mean,
              r.quality.sj_count_nonpositive, u.untangle.rounds, u.untangle.iterations,
              u.untangle.time_s, u.optimize.time_s, total);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"untangling benchmark"};
  app.require_subcommand(1);
  std::vector<std::string> files;
  std::string pillow = "auto";
  bool greedy = false, family = false;
  auto* mesh = app.add_subcommand("mesh", "full pipeline on surfaces");
  mesh->add_option("FILE", files, "surface files");
  mesh->add_option("--pillow", pillow, "auto|all|none")->capture_default_str();
  double forced_sj = 0.2;
  int grow = 2;
  mesh->add_option("--forced-sj", forced_sj, "PillowParams::forced_sj")->capture_default_str();
  mesh->add_option("--grow", grow, "PillowParams::grow")->capture_default_str();
  mesh->add_flag("--greedy", greedy, "plain greedy elimination instead of the planner");
  mesh->add_flag("--family", family, "also generated surfaces (cubed spheres, voxel solids, pillowed)");
  std::vector<int> sizes{10, 22, 46};
  int threads = 0;
  double jitter = 0.3;
  auto* scaling = app.add_subcommand("scaling", "optimizer alone on jittered cubed spheres");
  scaling->add_option("--sizes", sizes, "n of the n^3-hex meshes")->delimiter(',');
  scaling->add_option("--threads", threads, "TBB threads (0 = default)");
  scaling->add_option("--jitter", jitter, "jittered() amount")->capture_default_str();
  std::string solver = "lbfgs";
  bool simplicial = false, no_mean_sweep = false;
  int up_final_polish_runs = UntangleParams{}.final_polish_runs;
  for (auto* sub : {mesh, scaling}) {
    sub->add_option("--solver", solver, "phase 1 minimizer: newton|lbfgs")->capture_default_str();
    sub->add_flag("--simplicial", simplicial, "Newton: CHOLMOD simplicial instead of supernodal");
    sub->add_flag("--no-mean-sweep", no_mean_sweep, "UntangleParams::local_all = false");
    sub->add_option("--final-polish-runs", up_final_polish_runs,
                    "UntangleParams::final_polish_runs (0 = skip the final polish)")
        ->check(CLI::Range(0, 100))->capture_default_str();
  }
  CLI11_PARSE(app, argc, argv);
  UntangleParams up;
  if (!parse_untangle_solver(solver, up.solver)) {
    std::fprintf(stderr, "unknown --solver %s\n", solver.c_str());
    return 1;
  }
  up.supernodal = !simplicial;
  up.local_all = !no_mean_sweep;
  up.final_polish_runs = up_final_polish_runs;
  std::unique_ptr<tbb::global_control> gc;
  if (threads > 0)
    gc = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);

  if (*mesh) {
    MeshParams params;
    params.untangle = up;
    params.search = !greedy;
    params.pillow.forced_sj = forced_sj;
    params.pillow.grow = grow;
    params.pillow.mode = pillow == "all" ? PillowMode::all
                         : pillow == "none" ? PillowMode::none : PillowMode::automatic;
    std::printf("pillow %s, solver %s%s\n\n| surface | hexes | forced (doublet/concave/fixed) | "
                "pillow set+new | placed min / mean | untangled min | final min / mean | "
                "untangle rounds/iters | untangle+opt | total |\n"
                "|---|---|---|---|---|---|---|---|---|---|\n", pillow.c_str(), solver.c_str(),
                solver == "newton" ? (simplicial ? " (simplicial)" : " (supernodal)") : "");
    for (const std::string& f : files) {
      PolygonSoup soup;
      Status st = read_surface(f, soup);
      if (!st.ok()) {
        std::printf("| %s | %s |\n", f.c_str(), to_string(st).c_str());
        continue;
      }
      std::string name = f.substr(f.find_last_of('/') + 1);
      mesh_row(name, soup, params);
    }
    if (family) {
      using namespace hexpeel::testing;
      std::vector<Generated> gs;
      for (int n : {4, 8, 12}) gs.push_back(cubed_sphere_equiangular(n));
      for (const char* s : {"L", "U", "T", "pocket", "notch", "stairs", "steps"})
        gs.push_back(named_solid(s, 2));
      for (uint64_t seed = 1; seed <= 6; ++seed) gs.push_back(random_voxel_solid(seed, 5, 20, 1));
      for (uint64_t seed = 1; seed <= 4; ++seed) gs.push_back(pillowed(cube(3, 3, 3), seed, 0.3));
      for (uint64_t seed = 1; seed <= 3; ++seed)
        gs.push_back(perturbed(cubed_sphere_equiangular(6), seed, 0.2));
      for (const Generated& g : gs) {
        if (g.surface.quads.empty()) continue;
        mesh_row(g.name, to_polygon_soup(g.surface), params);
      }
    }
  }
  if (*scaling) {
    std::printf("solver %s%s\n\n| hexes | free vertices | forced (<=0) | placed min | "
                "untangle: rounds/iters/evals/factorizations | untangle time (solve) | min | "
                "optimize: rounds/evals/time | min | mean | total | corner-evals/s |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|---|\n", solver.c_str(),
                solver == "newton" ? (simplicial ? " (simplicial)" : " (supernodal)") : "");
    for (int n : sizes) {
      testing::Generated g = testing::jittered(testing::cubed_sphere_equiangular(n), 7, jitter);
      HexMesh m = g.known_mesh;
      std::vector<uint8_t> fixed(m.points.size(), 0);
      for (int32_t v = 0; v < g.surface.num_points(); ++v) fixed[v] = 1;
      UntangleResult u = run_untangle(m, fixed, up);
      const UntangleStats& s = u.stats;
      const double corner_evals =
          static_cast<double>(s.untangle.corner_evaluations + s.optimize.corner_evaluations);
      std::printf("| %d | %d | %d (%d) | %.3f (%d<=0) | %d/%d/%d/%d | %.2f s (%.2f s) | %.3f (%d<=0) | "
                  "%d/%d/%.2f s | %.3f (%d<=0) | %.4f | %.2f s | %.3g |\n",
                  m.num_hexes(), s.free_vertices, s.forced_corners, s.forced_nonpositive,
                  s.untangle.min_sj_before, s.untangle.nonpositive_before, s.untangle.rounds,
                  s.untangle.iterations, s.untangle.evaluations, s.untangle.factorizations,
                  s.untangle.time_s, s.untangle.solve_time_s, s.untangle.min_sj_after,
                  s.untangle.nonpositive_after, s.optimize.rounds, s.optimize.evaluations,
                  s.optimize.time_s, s.optimize.min_sj_after, s.optimize.nonpositive_after,
                  run_quality(u.mesh).sj_mean, s.time_s,
                  corner_evals / std::max(1e-9, s.time_s));
      std::fflush(stdout);
    }
  }
  return 0;
}
