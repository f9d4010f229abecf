// hexpeel_corpus: meshes every surface of a folder (each in its own process, for its peak memory)
// and writes a CSV and a markdown table: name, quads, chords, status, hexes, min/mean SJ, time per
// stage, peak memory, and the reference figures when a reference TSV is given
// (columns: name, reference_hexes, reference_min_sj, reference_mean_sj).
#include "bench_util.h"
#include "hexpeel/io.h"
#include "hexpeel/pipeline.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

using namespace hexpeel;
namespace fs = std::filesystem;

namespace {

struct Reference {
  std::string hexes, min_sj, mean_sj;
};

std::map<std::string, Reference> read_reference(const std::string& path) {
  std::map<std::string, Reference> out;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> cols;
    std::stringstream ss(line);
    std::string c;
    while (std::getline(ss, c, '\t')) cols.push_back(c);
    if (cols.size() < 2 || cols[0] == "name") continue;
    cols.resize(4);
    out[cols[0]] = {cols[1], cols[2], cols[3]};
  }
  return out;
}

std::string fmt(double v, const char* f = "%.3f") {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Mesh every surface in a folder and tabulate the results"};
  std::string dir, reference, csv = "corpus.csv", md = "corpus.md", meshes;
  double time_limit = 120.0;
  bool repair_surface = false;
  app.add_option("DIR", dir, "folder of surfaces (.obj .off .ply .mesh .msh .vtk)")->required();
  app.add_option("--reference", reference, "TSV: name, reference_hexes, reference_min_sj, reference_mean_sj");
  app.add_option("--csv", csv, "CSV output")->capture_default_str();
  app.add_option("--md", md, "markdown output")->capture_default_str();
  app.add_option("--meshes", meshes, "also write each hex mesh (.vtk) into this folder");
  app.add_option("--time-limit", time_limit, "elimination time limit per surface (s)")->capture_default_str();
  app.add_flag("--repair-surface", repair_surface,
               "mesh surfaces with self-crossing chords or odd counts refined (hexpeel mesh "
               "--repair-surface); quads is then the refined count");
  CLI11_PARSE(app, argc, argv);

  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file() && is_surface_extension(e.path())) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  auto ref = reference.empty() ? std::map<std::string, Reference>{} : read_reference(reference);
  if (!meshes.empty()) fs::create_directories(meshes);

  std::string csv_text =
      "name,quads,chords,status,hexes,ref_hexes,min_sj,mean_sj,ref_min_sj,ref_mean_sj,"
      "sj_le_0,interior_singular_edges,read_s,check_s,elimination_s,reconstruction_s,"
      "pillow_s,placement_s,untangle_s,quality_s,total_s,peak_rss_mb,message\n";
  std::string md_text =
      "| surface | quads | chords | status | hexes (ref) | min SJ (ref) | mean SJ (ref) | SJ<=0 | "
      "int. sing. edges | elim s | recon s | untangle s | total s | peak MB |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  int ok = 0;
  for (const fs::path& f : files) {
    const std::string name = f.stem().string();
    bench::Isolated r = bench::run_isolated([&]() {
      nlohmann::json j;
      auto t0 = std::chrono::steady_clock::now();
      PolygonSoup soup;
      Status st = read_surface(f, soup);
      double read_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (!st.ok()) return nlohmann::json{{"status", std::string(to_string(st.code))}, {"message", st.message}};
      MeshParams p;
      p.elimination.time_limit_s = time_limit;
      p.repair_surface = repair_surface;
      MeshResult m = run_mesh(soup, p);
      j = to_json(m);
      j["timings_s"]["read"] = read_s;
      j["quads"] = m.diagnosis.validation.surface.num_quads();
      if (m.status.ok() && !meshes.empty()) write_hex_mesh(fs::path(meshes) / (name + ".vtk"), m.mesh);
      return j;
    });
    const nlohmann::json& j = r.result;
    std::string status = r.failure.empty() ? j.value("status", "?") : "CRASH(" + r.failure + ")";
    bool meshed = status == "ok";
    ok += meshed;
    const Reference rf = ref.count(name) ? ref[name] : Reference{};
    auto num = [&](const char* a, const char* b) -> double {
      return j.contains(a) && j[a].contains(b) && j[a][b].is_number() ? j[a][b].get<double>() : NAN;
    };
    double total = 0;
    for (const char* s : {"read", "check", "elimination", "reconstruction", "pillow", "placement",
                          "untangle", "quality", "pillow_retry", "intrusion_cover",
                          "other_orders"})
      total += std::isnan(num("timings_s", s)) ? 0.0 : num("timings_s", s);
    std::string hexes = meshed ? std::to_string(j.value("hexes", 0)) : "-";
    std::string minsj = meshed ? fmt(num("scaled_jacobian", "min")) : "-";
    std::string meansj = meshed ? fmt(num("scaled_jacobian", "mean")) : "-";
    std::string nonpos = meshed ? std::to_string(j["scaled_jacobian"].value("count_nonpositive", 0)) : "-";
    std::string sing = meshed ? std::to_string(j["singular_edges"].value("interior", 0)) : "-";
    std::string msg = j.value("message", "");
    std::replace(msg.begin(), msg.end(), ',', ';');
    csv_text += name + "," + std::to_string(j.value("quads", 0)) + "," +
                std::to_string(j.contains("chords") ? j["chords"].value("count", 0) : 0) + "," + status +
                "," + hexes + "," + rf.hexes + "," + minsj + "," + meansj + "," + rf.min_sj + "," +
                rf.mean_sj + "," + nonpos + "," + sing + "," + fmt(num("timings_s", "read"), "%.4f") +
                "," + fmt(num("timings_s", "check"), "%.4f") + "," +
                fmt(num("timings_s", "elimination"), "%.4f") + "," +
                fmt(num("timings_s", "reconstruction"), "%.4f") + "," +
                fmt(num("timings_s", "pillow"), "%.4f") + "," +
                fmt(num("timings_s", "placement"), "%.4f") + "," +
                fmt(num("timings_s", "untangle"), "%.4f") + "," +
                fmt(num("timings_s", "quality"), "%.4f") + "," + fmt(total, "%.4f") + "," +
                fmt(r.peak_rss_kb / 1024.0, "%.1f") + "," + msg + "\n";
    auto withref = [](const std::string& v, const std::string& r) { return r.empty() ? v : v + " (" + r + ")"; };
    md_text += "| " + name + " | " + std::to_string(j.value("quads", 0)) + " | " +
               std::to_string(j.contains("chords") ? j["chords"].value("count", 0) : 0) + " | " + status +
               " | " + withref(hexes, rf.hexes) + " | " + withref(minsj, rf.min_sj) + " | " +
               withref(meansj, rf.mean_sj) + " | " + nonpos + " | " + sing + " | " +
               fmt(num("timings_s", "elimination"), "%.3f") + " | " +
               fmt(num("timings_s", "reconstruction"), "%.3f") + " | " +
               fmt(num("timings_s", "untangle"), "%.3f") + " | " + fmt(total) + " | " +
               fmt(r.peak_rss_kb / 1024.0, "%.0f") + " |\n";
    std::printf("%-28s %-10s hexes %-8s min SJ %-7s mean SJ %-7s %.2f s %s\n", name.c_str(),
                status.c_str(), hexes.c_str(), minsj.c_str(), meansj.c_str(), total,
                meshed ? "" : msg.substr(0, 100).c_str());
    std::fflush(stdout);
  }
  md_text += "\n" + std::to_string(ok) + " of " + std::to_string(files.size()) + " surfaces meshed.\n";
  Status a = write_text_file(csv, csv_text), b = write_text_file(md, md_text);
  if (!a.ok() || !b.ok()) {
    std::fprintf(stderr, "hexpeel_corpus: %s %s\n", to_string(a).c_str(), to_string(b).c_str());
    return 2;
  }
  std::printf("%d of %zu meshed; wrote %s and %s\n", ok, files.size(), csv.c_str(), md.c_str());
  return 0;
}
