// hexpeel_compare_methods: the paper's comparison (Kremer et al. 2013, section 6) of the original
// elimination order (Müller-Hannemann) with the kremer rules, on every surface of the folders
// given and on the generated concave solids (L, U, T, pocket, notch, stairs, steps at m = 1..3
// and random voxel solids). Each run is a child process (a crash cannot end the table). Per
// surface and method: status, hexes, min/mean/max scaled Jacobian, hexes <= 0, interior singular
// edges, concave steps and invalid intrusions. Writes a markdown table and a summary. By default
// the greedy order (no search) and the simple harmonic placement (no pillowing, no untangling),
// so the table shows what the order rules do; --search and --optimize switch those stages on.
#include "bench_util.h"
#include "hexpeel/io.h"
#include "hexpeel/pipeline.h"
#include "support/generators.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>

using namespace hexpeel;
namespace fs = std::filesystem;
namespace ht = hexpeel::testing;

namespace {

std::string fmt(double v, const char* f = "%.3f") {
  if (std::isnan(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

struct Variant {
  std::string name;
  MeshParams params;
};

struct Outcome {
  std::string status = "?";
  std::string message;
  int hexes = 0, nonpositive = 0, singular = 0, concave_steps = 0, invalid_intrusions = 0;
  double sj_min = NAN, sj_mean = NAN, sj_max = NAN;
  bool ok() const { return status == "ok"; }
  bool good() const { return ok() && nonpositive == 0; }
};

Outcome run_one(const std::function<bool(PolygonSoup&)>& load, const MeshParams& params) {
  bench::Isolated r = bench::run_isolated([&]() {
    PolygonSoup soup;
    if (!load(soup)) return nlohmann::json{{"status", "unreadable"}};
    return to_json(run_mesh(soup, params));
  });
  Outcome o;
  const nlohmann::json& j = r.result;
  if (!r.failure.empty()) {
    o.status = "crash";
    return o;
  }
  o.status = j.value("status", "?");
  o.message = j.value("message", "");
  if (j.contains("plan")) o.concave_steps = j["plan"].value("concave_steps", 0);
  if (j.contains("reconstruction") && j["reconstruction"].contains("invalid_intrusion_steps"))
    o.invalid_intrusions = static_cast<int>(j["reconstruction"]["invalid_intrusion_steps"].size());
  if (!o.ok()) return o;
  o.hexes = j.value("hexes", 0);
  const auto& sj = j["scaled_jacobian"];
  auto num = [](const nlohmann::json& x, const char* k) {
    return x.contains(k) && x[k].is_number() ? x[k].get<double>() : NAN;
  };
  o.sj_min = num(sj, "min");
  o.sj_mean = num(sj, "mean");
  o.sj_max = num(sj, "max");
  o.nonpositive = sj.value("count_nonpositive", 0);
  o.singular = j["singular_edges"].value("interior", 0);
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Compare the original and kremer elimination orders (status, hexes, SJ, singular edges)"};
  std::vector<std::string> dirs;
  std::string md = "compare_methods.md";
  double time_limit = 120.0;
  bool generated = true, fallback = false;
  int random_solids = 10;
  app.add_option("DIR", dirs, "folders of surfaces (.obj .off .ply .mesh .msh .vtk)");
  app.add_option("--md", md, "markdown output")->capture_default_str();
  app.add_option("--time-limit", time_limit, "elimination time limit per run (s)")->capture_default_str();
  app.add_option("--random", random_solids, "number of random voxel solids")->capture_default_str();
  app.add_flag("!--no-generated", generated, "skip the generated concave solids");
  app.add_flag("--fallback", fallback, "kremer twice: strict intrusion, and with fallback_to_extrusion");
  bool search = false, optimize = false;
  app.add_flag("--search", search, "plan with the search portfolio instead of the greedy order");
  app.add_flag("--optimize", optimize, "pillow and untangle (default: the simple placement only)");
  double concave_min = OrderParams{}.concave_min;
  app.add_option("--concave-min", concave_min, "kremer: minimum concavity weight")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  std::vector<Variant> variants(2);
  variants[0].name = "original";
  variants[0].params.elimination.order.method = Method::original;
  variants[1].name = "kremer";
  variants[1].params.elimination.order.method = Method::kremer;
  variants[1].params.elimination.order.concave_min = concave_min;
  variants[1].params.reconstruction.fallback_to_extrusion = !fallback;
  if (fallback) {
    variants[1].name = "kremer-strict";
    variants.push_back(variants[1]);
    variants.back().name = "kremer";
    variants.back().params.reconstruction.fallback_to_extrusion = true;
  }
  for (Variant& v : variants) {
    v.params.alternatives = 0;  // each variant's own order, not the pipeline's fallbacks
    v.params.elimination.time_limit_s = time_limit;
    v.params.search = search;
    if (!optimize) {
      v.params.pillow.mode = PillowMode::none;
      v.params.untangle.untangle = v.params.untangle.optimize = false;
    }
  }

  struct Case {
    std::string name;
    bool voxel = false;  // has an all-cube mesh with SJ = 1
    std::function<bool(PolygonSoup&)> load;
  };
  std::vector<Case> cases;
  for (const std::string& d : dirs) {
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(d))
      if (e.is_regular_file() && is_surface_extension(e.path())) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const fs::path& f : files) {
      const std::string stem = f.stem().string();
      cases.push_back({stem, stem.rfind("vox_", 0) == 0 || stem.rfind("cube_", 0) == 0,
                       [f](PolygonSoup& s) { return read_surface(f, s).ok(); }});
    }
  }
  if (generated) {
    std::vector<ht::Generated> gs;
    for (const char* shape : {"L", "U", "T", "pocket", "notch", "stairs", "steps"})
      for (int m = 1; m <= 3; ++m) gs.push_back(ht::named_solid(shape, m));
    for (int i = 1; i <= random_solids; ++i)
      gs.push_back(ht::random_voxel_solid(static_cast<uint64_t>(i), 4, 6 + i, 1 + (i % 3 == 0)));
    for (ht::Generated& g : gs) {
      auto surf = std::make_shared<QuadSurface>(std::move(g.surface));
      cases.push_back({"gen:" + g.name, true, [surf](PolygonSoup& s) {
                         s = to_polygon_soup(*surf);
                         return surf->num_quads() > 0;
                       }});
    }
  }

  std::string head = "| surface |", rule = "|---|";
  for (const char* col : {"status", "hexes", "min SJ", "mean SJ", "max SJ", "SJ<=0", "int. sing."}) {
    head += std::string(" ") + col + " |";
    rule += "---|";
  }
  head += " concave steps | invalid intr. |\n";
  rule += "---|---|\n";
  std::string table = "Columns: " ;
  for (size_t v = 0; v < variants.size(); ++v) table += (v ? " / " : "") + variants[v].name;
  table += "\n\n" + head + rule;

  struct Tally {
    int ok = 0, good = 0, voxel_ok = 0, voxel_good = 0, invalid = 0;
  };
  std::vector<Tally> tally(variants.size());
  int64_t sing_both[2] = {0, 0};
  int both = 0, voxel_cases = 0;
  for (const Case& c : cases) {
    std::vector<Outcome> out;
    for (const Variant& v : variants) out.push_back(run_one(c.load, v.params));
    voxel_cases += c.voxel;
    for (size_t v = 0; v < variants.size(); ++v) {
      tally[v].ok += out[v].ok();
      tally[v].good += out[v].good();
      tally[v].voxel_ok += c.voxel && out[v].ok();
      tally[v].voxel_good += c.voxel && out[v].good();
      tally[v].invalid += out[v].status == "invalid_intrusion";
    }
    if (out[0].ok() && out[1].ok()) {
      ++both;
      sing_both[0] += out[0].singular;
      sing_both[1] += out[1].singular;
    }
    auto cell = [&](const std::function<std::string(const Outcome&)>& f) {
      std::string s;
      for (size_t v = 0; v < out.size(); ++v) s += (v ? " / " : "") + f(out[v]);
      return " " + s + " |";
    };
    auto when_ok = [](const Outcome& o, std::string s) { return o.ok() ? s : std::string("-"); };
    table += "| " + c.name + " |" + cell([](const Outcome& o) { return o.status; }) +
             cell([&](const Outcome& o) { return when_ok(o, std::to_string(o.hexes)); }) +
             cell([&](const Outcome& o) { return when_ok(o, fmt(o.sj_min, "%.2f")); }) +
             cell([&](const Outcome& o) { return when_ok(o, fmt(o.sj_mean, "%.2f")); }) +
             cell([&](const Outcome& o) { return when_ok(o, fmt(o.sj_max, "%.2f")); }) +
             cell([&](const Outcome& o) { return when_ok(o, std::to_string(o.nonpositive)); }) +
             cell([&](const Outcome& o) { return when_ok(o, std::to_string(o.singular)); }) +
             cell([](const Outcome& o) { return std::to_string(o.concave_steps); }) +
             cell([](const Outcome& o) { return std::to_string(o.invalid_intrusions); }) + "\n";
    std::printf("%-28s", c.name.c_str());
    for (size_t v = 0; v < out.size(); ++v)
      std::printf(" | %-9s %6d hx min %5s ≤0 %3d sing %3d", out[v].status.substr(0, 9).c_str(),
                  out[v].hexes, fmt(out[v].sj_min, "%.2f").c_str(), out[v].nonpositive,
                  out[v].singular);
    std::printf("\n");
    for (size_t v = 0; v < out.size(); ++v)
      if (!out[v].ok()) std::printf("    %s: %s\n", variants[v].name.c_str(), out[v].message.substr(0, 160).c_str());
    std::fflush(stdout);
  }
  std::string summary = "\n| method | meshed | meshed, all SJ > 0 | voxel solids meshed | voxel, all SJ > 0 | "
                        "invalid intrusion |\n|---|---|---|---|---|---|\n";
  for (size_t v = 0; v < variants.size(); ++v)
    summary += "| " + variants[v].name + " | " + std::to_string(tally[v].ok) + "/" +
               std::to_string(cases.size()) + " | " + std::to_string(tally[v].good) + " | " +
               std::to_string(tally[v].voxel_ok) + "/" + std::to_string(voxel_cases) + " | " +
               std::to_string(tally[v].voxel_good) + " | " + std::to_string(tally[v].invalid) + " |\n";
  summary += "\nInterior singular edges over the " + std::to_string(both) +
             " surfaces both methods mesh: " + variants[0].name + " " + std::to_string(sing_both[0]) + ", " + variants[1].name + " " +
             std::to_string(sing_both[1]) + ".\n";
  table += summary;
  std::printf("%s", summary.c_str());
  Status w = write_text_file(md, table);
  if (!w.ok()) {
    std::fprintf(stderr, "hexpeel_compare_methods: %s\n", to_string(w).c_str());
    return 2;
  }
  std::printf("wrote %s\n", md.c_str());
  return 0;
}
