// hexpeel command line: the only code that parses argv, prints, or picks file names.
//
//   hexpeel check IN [--sharp-angle DEG] [--json FILE]
//   hexpeel mesh IN -o OUT [--report FILE] [--dump-stuck FILE] [--sharp-angle DEG]
//                [--time-limit S] [--planner search|greedy] [--plan-budget S]
//                [--improve-budget S] [--seed N] [--side-rule cost|heavier] [--side-threshold W]
//                [--method original|kremer] [--no-zero-volume] [--no-enclosed] [--no-concave]
//                [--no-false-positive] [--no-concave-waits] [--strict-intrusion]
//                [--no-intrusion-cover] [--intrusion-flip-rounds N]
//                [--pillow auto|all|none] [--no-untangle] [--no-optimize]
//                [--polish-iterations N] [--quality-passes N] [--regularization W]
//                [--final-polish-runs N] [--final-polish-softmin G] [--final-polish-rounds N]
//                [--no-mean-sweep]
//                [--solver lbfgs|newton] [--alternatives N]
//                [--alternatives-always] [--threads N] [--quiet]
//   hexpeel quality MESH [--surface IN] [--json FILE] [--threads N]
//
// Exit codes: 0 success, 1 usage error, 2 bad input or file problem (for `quality`: also a mesh
// with hexes of scaled Jacobian <= 0, not a ball, or not bounded by --surface), 3 meshing failed,
// 4 internal error (a bug: please report it with the input), 5 (`mesh`) the mesh was written but
// has hexes with scaled Jacobian <= 0 (a warning on stderr says how many).
#include "hexpeel/diagnosis.h"
#include "hexpeel/html_report.h"
#include "hexpeel/io.h"
#include "hexpeel/pipeline.h"
#include "hexpeel/quality.h"
#include "hexpeel/tet_fill.h"

#include <algorithm>
#include <filesystem>
#include <CLI/CLI.hpp>
#include <tbb/global_control.h>

#include <chrono>
#include <cstdio>
#include <exception>
#include <iostream>
#include <memory>
#include <string>
#include <unistd.h>

namespace {

using namespace hexpeel;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

int report_error(const Status& s) {
  std::fprintf(stderr, "hexpeel: error: %s\n", to_string(s).c_str());
  return exit_code(s);
}

/// Progress on stderr, shown once a run has taken more than a second (short runs stay quiet).
/// On a terminal: one line, redrawn at most every 0.25 s. Otherwise (a log file, a pipe): a line
/// when the stage changes and at most every 5 s within a stage, so a long run's log stays short.
struct Progress {
  bool enabled = true;
  bool tty = isatty(fileno(stderr)) != 0;
  Clock::time_point start = Clock::now(), last = start;
  std::string last_stage;
  bool shown = false;  ///< a terminal line is showing (a message must clear it first)

  void operator()(std::string_view stage, double fraction) {
    if (!enabled) return;
    auto now = Clock::now();
    if (std::chrono::duration<double>(now - start).count() < 1.0) return;
    const bool new_stage = stage != last_stage;
    const double interval = tty ? 0.25 : 5.0;
    if (!new_stage && std::chrono::duration<double>(now - last).count() < interval &&
        !(tty && fraction >= 1.0))
      return;
    last = now;
    last_stage = stage;
    std::fprintf(stderr, "%s%-16.*s %5.1f%%  %6.1fs%s", tty ? "\r" : "",
                 static_cast<int>(stage.size()), stage.data(), 100.0 * fraction,
                 std::chrono::duration<double>(now - start).count(), tty ? "" : "\n");
    std::fflush(stderr);
    shown = tty;
  }
  /// Ends a terminal line that is showing, so that what is printed next starts on its own line.
  void finish() {
    if (shown) std::fprintf(stderr, "\n");
    shown = false;
  }
};

Context make_context(Progress* progress, bool quiet) {
  Context ctx;
  ctx.log = [quiet, progress](LogLevel level, std::string_view msg) {
    if (quiet && level != LogLevel::warning) return;
    if (level == LogLevel::debug) return;
    if (progress) progress->finish();
    std::fprintf(stderr, "hexpeel: %s%.*s\n", level == LogLevel::warning ? "warning: " : "",
                 static_cast<int>(msg.size()), msg.data());
  };
  if (progress) ctx.progress = [progress](std::string_view s, double f) { (*progress)(s, f); };
  return ctx;
}

/// A surface file that is also a volume mesh: only its faces are the surface.
void warn_hexes_ignored(const std::string& in, int64_t hexes) {
  if (hexes > 0)
    std::fprintf(stderr,
                 "hexpeel: warning: %s: %lld hexahedra ignored: only the file's faces are read as "
                 "the surface\n",
                 in.c_str(), static_cast<long long>(hexes));
}

int cmd_check(const std::string& in, double sharp_angle, const std::string& json_out) {
  PolygonSoup soup;
  int64_t hexes_ignored = 0;
  Status st = read_surface(in, soup, &hexes_ignored);
  if (!st.ok()) return report_error(st);
  warn_hexes_ignored(in, hexes_ignored);
  SurfaceDiagnosis d = diagnose_surface(soup, sharp_angle, make_context(nullptr, false));
  std::printf("%s", to_text(d).c_str());
  std::printf("path: %s\n", mesh_path(d).c_str());
  nlohmann::json j = to_json(d);
  if (d.status.code == StatusCode::self_intersecting_chord ||
      d.status.code == StatusCode::odd_quad_count) {
    // What `mesh --repair-surface` would do with it (an odd surface checked again, odd allowed).
    ValidationParams odd_ok;
    odd_ok.allow_odd = true;
    const SurfaceDiagnosis e = d.status.code == StatusCode::odd_quad_count
                                   ? diagnose_surface(soup, sharp_angle, Context{}, odd_ok)
                                   : d;
    if (e.validation.status.ok()) {
      const SurfaceRepair rep = repair_surface(e.validation.surface);
      if (rep.status.ok())
        std::printf("with --repair-surface: split into six, %d quads, filled through tetrahedra%s "
                    "(--repair-fill elimination: refined into %d quads, %zu of %d split into six, "
                    "the rest into four, every chord simple)\n",
                    6 * rep.stats.input_quads,
                    tet_fill_available() ? "" : " (not in this build: no gmsh library)",
                    rep.stats.output_quads, rep.stats.six_split.size(), rep.stats.input_quads);
      else
        std::printf("with --repair-surface: %s\n", rep.status.message.c_str());
      j["repair"] = to_json(rep.stats);
    }
  }
  if (!json_out.empty()) {
    Status w = write_text_file(json_out, j.dump(2) + "\n");
    if (!w.ok()) return report_error(w);
  }
  if (!d.status.ok()) {
    std::printf("verdict: %s cannot be given to the mesher (%s)\n", in.c_str(),
                std::string(to_string(d.status.code)).c_str());
    std::fprintf(stderr, "hexpeel: error: %s: cannot be meshed: %s\n", in.c_str(),
                 to_string(d.status).c_str());
    return exit_code(d.status);
  }
  std::printf("verdict: %s can be given to the mesher\n", in.c_str());
  return 0;
}

/// The HTML report of `mesh` (quality `q`) at `path`, titled by the file name of `source`.
Status write_html(const std::string& path, const HexMesh& mesh, const QualityReport& q,
                  const std::string& source) {
  HtmlReportParams hp;
  hp.title = std::filesystem::path(source).filename().string();
  return write_text_file(path, html_report(mesh, q, hp));
}

int cmd_mesh(const std::string& in, const std::string& out, const std::string& report,
             const std::string& dump_stuck, const std::string& repaired_out,
             const std::string& html_out, const MeshParams& params, bool patch_sets, bool quiet) {
  if (!is_hex_mesh_extension(out))
    return report_error(Status::error(StatusCode::unsupported_format,
                                      "output '" + out + "': use .vtk, .vtu, .mesh, .msh, .inp, .exo or .e"));
  if (!dump_stuck.empty() && !is_surface_extension(dump_stuck))
    return report_error(Status::error(StatusCode::unsupported_format,
                                      "--dump-stuck '" + dump_stuck + "': use .obj or .off"));
  if (!repaired_out.empty() && !is_surface_extension(repaired_out))
    return report_error(Status::error(StatusCode::unsupported_format,
                                      "--repaired-surface '" + repaired_out + "': use .obj or .off"));
  if (patch_sets && !carries_boundary_patches(out))
    return report_error(Status::error(StatusCode::unsupported_format,
                                      "--patch-sets: output '" + out + "' has no boundary groups; "
                                      "use .exo, .e, .inp, .msh or .mesh"));
  if (!repaired_out.empty() && !params.repair_surface)
    return report_error(Status::error(StatusCode::unsupported_format,
                                      "--repaired-surface needs --repair-surface"));
  Progress progress;
  progress.enabled = !quiet;
  Context ctx = make_context(&progress, quiet);
  auto t = Clock::now();
  PolygonSoup soup;
  int64_t hexes_ignored = 0;
  Status st = read_surface(in, soup, &hexes_ignored);
  const double read_s = seconds_since(t);
  if (!st.ok()) return report_error(st);
  warn_hexes_ignored(in, hexes_ignored);

  MeshResult r = run_mesh(soup, params, ctx);
  progress.finish();
  double write_s = 0.0;
  if (r.status.ok()) {
    t = Clock::now();
    BoundaryPatches patches;
    if (patch_sets) patches = boundary_patches(r, params.sharp_angle_deg);
    Status w = write_hex_mesh(out, r.mesh, patch_sets ? &patches : nullptr);
    if (w.ok() && patch_sets && !quiet)
      std::printf("boundary patches: %d (cut along edges sharper than %g degrees), written as "
                  "patch_1 .. patch_%d\n", patches.count, params.sharp_angle_deg, patches.count);
    if (w.ok() && !repaired_out.empty()) {
      // The mesh's boundary: the repaired surface, or the input itself when it needed none.
      w = write_surface(repaired_out, r.repair.applied ? r.repaired_surface
                                                       : r.diagnosis.validation.surface);
      if (!w.ok()) std::filesystem::remove(out);
    }
    if (w.ok() && !html_out.empty()) {
      w = write_html(html_out, r.mesh, r.quality, in);
      if (!w.ok()) {
        std::filesystem::remove(out);
        if (!repaired_out.empty()) std::filesystem::remove(repaired_out);
      }
    }
    write_s = seconds_since(t);
    if (!w.ok()) r.status = w;
  }
  if (!report.empty()) {
    nlohmann::json j = to_json(r);
    j["timings_s"]["read"] = read_s;
    // The budgets, passes and retries this run used (what --effort and their options set).
    j["params"] = effort_to_json(params);
    j["timings_s"]["write"] = write_s;
    Status w = write_text_file(report, j.dump(2) + "\n");
    if (!w.ok()) return report_error(w);
  }
  if (!r.status.ok()) {
    if (r.status.code == StatusCode::stuck && !dump_stuck.empty() && r.stuck_surface.num_quads() > 0) {
      Status w = write_surface(dump_stuck, r.stuck_surface);
      if (!w.ok()) report_error(w);
      else std::fprintf(stderr, "hexpeel: stuck surface written to %s\n", dump_stuck.c_str());
    }
    return report_error(r.status);
  }
  if (!quiet) {
    const QualityReport& q = r.quality;
    std::printf("%s: %d quads, %d chords -> %s: %d hexes in %.2f s (method %s, %d concave "
                "steps)\n", in.c_str(),
                r.diagnosis.validation.surface.num_quads(), r.diagnosis.chord_stats.count,
                out.c_str(), q.hexes,
                read_s + r.timings.check_s + r.timings.elimination_s + r.timings.reconstruction_s +
                    r.timings.pillow_s + r.timings.placement_s + r.timings.untangle_s +
                    r.timings.quality_s + r.timings.pillow_retry_s + r.timings.other_orders_s +
                    r.timings.intrusion_cover_s +
                    write_s,
                std::string(to_string(r.method.method)).c_str(), r.plan.stats.concave_steps);
    if (r.tries.size() > 1) {
      std::printf("elimination orders tried:");
      for (size_t i = 0; i < r.tries.size(); ++i) {
        const OrderTry& t = r.tries[i];
        std::printf("%s %s/%s ", i ? ";" : "", std::string(to_string(t.method)).c_str(),
                    std::string(to_string(t.side_rule)).c_str());
        if (t.same_plan_as >= 0)
          std::printf("same plan as try %d", t.same_plan_as + 1);
        else if (t.skipped_plan_hexes > 0)
          std::printf("not built (plan of %lld hexes)", static_cast<long long>(t.skipped_plan_hexes));
        else if (t.status == StatusCode::ok)
          std::printf("min %.4f, %d hexes <= 0", t.min_sj, t.nonpositive);
        else
          std::printf("%s", std::string(to_string(t.status)).c_str());
        if (static_cast<int32_t>(i) == r.kept_try) std::printf(" (kept)");
      }
      std::printf("\n");
    }
    std::printf("scaled Jacobian min %.4f mean %.4f max %.4f, %d hexes <= 0; "
                "singular edges: %d interior, %d boundary\n",
                q.sj_min, q.sj_mean, q.sj_max, q.sj_count_nonpositive, q.singular_edges_interior,
                q.singular_edges_boundary);
    if (r.pillow.forced > 0)
      std::printf("forced configurations: %d (%d flat doublets, %d concave corners, %d fixed "
                  "corners, %d collinear); pillow: %d hexes in the shrink set%s, %d new hexes\n",
                  r.pillow.forced, r.pillow.flat_doublets, r.pillow.concave_corners,
                  r.pillow.fixed_corners, r.pillow.collinear, r.pillow.shrink_set,
                  r.pillow.whole_boundary ? " (whole boundary)" : "", r.pillow.new_hexes);
    if (r.pillow_retry.tried) {
      const PillowRetryStats& pr = r.pillow_retry;
      std::printf("pillow retry (the minimum was a corner fixed by the boundary, %.4f): corners up "
                  "to %.4f pillowed, ", pr.forced_min_sj, pr.forced_sj);
      if (pr.retry_ok)
        std::printf("%d hexes min %.4f mean %.4f", pr.retry_hexes, pr.retry_min_sj,
                    pr.retry_mean_sj);
      else
        std::printf("failed");
      std::printf(" against %d hexes min %.4f mean %.4f; %s kept\n", pr.first_hexes,
                  pr.first_min_sj, pr.first_mean_sj, pr.kept ? "the retry" : "the first mesh");
    }
    if (r.pillow_repair.tried) {
      const PillowRetryStats& pr = r.pillow_repair;
      std::printf("repair pillow: %d of %d rounds kept (%d new hexes), %d hexes <= 0 (min "
                  "%.4f) against %d (min %.4f) before\n",
                  pr.rounds_kept, pr.rounds, pr.new_hexes, pr.retry_nonpositive, pr.retry_min_sj,
                  pr.first_nonpositive, pr.first_min_sj);
    }
    if (q.sj_count_nonpositive > 0) {
      if (params.untangle.untangle)
        std::printf("note: %d hexes are inverted or degenerate after untangling (%d corners are "
                    "fixed by the boundary at det <= 0%s)\n",
                    q.sj_count_nonpositive, r.untangle.forced_nonpositive,
                    r.pillow.whole_boundary ? "; the whole boundary is pillowed already"
                                            : "; try --pillow all");
      else
        std::printf("note: interior vertices are placed by a harmonic solve only (--no-untangle); "
                    "%d hexes are inverted or degenerate\n", q.sj_count_nonpositive);
    }
  }
  if (r.quality.sj_count_nonpositive > 0) {  // written, but not fit for a solver: say so
    std::fprintf(stderr,
                 "hexpeel: warning: %s has %d hexes with scaled Jacobian <= 0 (min %.4g); "
                 "exit code 5\n",
                 out.c_str(), r.quality.sj_count_nonpositive, r.quality.sj_min);
    return 5;
  }
  return 0;
}

int cmd_quality(const std::string& mesh_path, const std::string& surface_path,
                const std::string& json_out, const std::string& html_out) {
  HexMesh mesh;
  int64_t others = 0;
  Status st = read_hex_mesh(mesh_path, mesh, &others);
  if (!st.ok()) return report_error(st);
  if (others > 0)
    std::fprintf(stderr, "hexpeel: warning: %s: %lld non-hex cells ignored\n", mesh_path.c_str(),
                 static_cast<long long>(others));
  QuadSurface surface;
  bool have_surface = !surface_path.empty();
  if (have_surface) {
    PolygonSoup soup;
    st = read_surface(surface_path, soup);
    if (!st.ok()) return report_error(st);
    ValidationResult v = run_validation(soup, {}, make_context(nullptr, false));
    if (!v.status.ok()) return report_error(v.status);
    surface = std::move(v.surface);
    // compare against the surface as given (validation may have dropped unused vertices only)
  }
  QualityReport q = run_quality(mesh, {}, have_surface ? &surface : nullptr);
  std::printf("%s", to_text(q).c_str());
  if (!json_out.empty()) {
    Status w = write_text_file(json_out, to_json(q).dump(2) + "\n");
    if (!w.ok()) return report_error(w);
  }
  if (!html_out.empty()) {
    Status w = write_html(html_out, mesh, q, mesh_path);
    if (!w.ok()) return report_error(w);
  }
  // A mesh that fails the check is bad input (exit 2; 1 is kept for usage errors).
  std::string why;
  if (q.sj_count_nonpositive > 0)
    why += std::to_string(q.sj_count_nonpositive) + " hexes have a scaled Jacobian <= 0; ";
  if (!q.is_ball) why += "the hexes do not form a ball (" + q.topology_message + "); ";
  if (!q.boundary_matches_surface.value_or(true))
    why += "its boundary differs from " + surface_path + " (" + q.boundary_message + "); ";
  if (why.empty()) return 0;
  why.resize(why.size() - 2);
  std::fprintf(stderr, "hexpeel: error: %s: %s\n", mesh_path.c_str(), why.c_str());
  return 2;
}

/// --effort: the budgets, passes and retries of a preset, each unless its own option was given.
/// "default" changes nothing.
void apply_effort(const std::string& effort, const CLI::App& mesh, MeshParams& p) {
  auto set = [&](const char* option, auto& field, auto value) {
    if (mesh.count(option) == 0) field = value;
  };
  if (effort == "fast") {
    set("--stuck-fill-budget", p.terminal.total_budget_s, 3.0);
    set("--quality-passes", p.untangle.quality_passes, 1);
    set("--final-polish-runs", p.untangle.final_polish_runs, 1);
    set("--final-polish-rounds", p.untangle.final_polish_rounds, 1);
    set("--alternatives", p.alternatives, 1);
    set("--repair-rounds", p.repair_rounds, 1);
    set("--intrusion-flip-rounds", p.intrusion_flip_rounds, 1);
  } else if (effort == "best") {
    set("--plan-budget", p.planner.budget_s, 60.0);
    set("--improve-budget", p.planner.improve_budget_s, 20.0);
    set("--quality-passes", p.untangle.quality_passes, 5);
    set("--final-polish-rounds", p.untangle.final_polish_rounds, 3);
    set("--alternatives-always", p.alternatives_always, true);
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"hexpeel: fill a closed genus-0 quad surface with hexahedra, keeping the surface"};
  app.set_version_flag("--version", "hexpeel 0.1.0");
  app.require_subcommand(1);

  std::string in, out, report, dump_stuck, json_out, surface, repaired_out, html_out;
  double sharp_angle = 60.0;
  bool quiet = false;
  MeshParams params;

  auto* check = app.add_subcommand("check", "Diagnose a quad surface: validity, chords, sharp edges. "
                                            "Exit 0 only if it can be given to the mesher.");
  check->add_option("IN", in, "surface file (.obj .off .ply .mesh .msh .vtk)")->required();
  check->add_option("--sharp-angle", sharp_angle, "deviation from flat (degrees) above which an edge is sharp")
      ->check(CLI::Range(0.0, 180.0))->capture_default_str();
  check->add_option("--json", json_out, "also write the diagnosis as JSON");

  auto* mesh = app.add_subcommand("mesh", "Fill a quad surface with hexes by dual cycle elimination.");
  mesh->add_option("IN", in, "surface file (.obj .off .ply .mesh .msh .vtk)")->required();
  mesh->add_option("-o,--output", out, "hex mesh to write (.vtk .vtu .mesh .msh .inp .exo .e)")->required();
  mesh->add_option("--report", report, "write a JSON report: quality, chords, steps, status, timings");
  mesh->add_option("--html", html_out,
                   "also write an HTML quality report: figures, histogram, worst hexes, 3D view "
                   "with a cutaway plane (self-contained; open it in a browser)");
  std::string repair_fill = "tets";
  mesh->add_option("--repair-fill", repair_fill,
                   "with --repair-surface: tets = the surface split into six, filled through "
                   "tetrahedra (4 hexes each); elimination = the refined surface by dual cycle "
                   "elimination; both = both, the better mesh kept")
      ->check(CLI::IsMember({"tets", "elimination", "both"}))->capture_default_str();
  mesh->add_flag("--repair-surface", params.repair_surface,
                 "a surface with a self-crossing chord or an odd quad count is refined (input "
                 "vertices kept, every quad split into 6) and that is meshed; the mesh's boundary "
                 "is the refined surface; see docs/cli.md");
  mesh->add_option("--repaired-surface", repaired_out,
                   "with --repair-surface: also write the mesh's boundary surface (.obj .off)");
  bool patch_sets = false;
  mesh->add_flag("--patch-sets", patch_sets,
                 "also write one boundary group per surface patch bounded by sharp edges "
                 "(--sharp-angle), named patch_1.. (.exo .e .inp .msh .mesh; .vtk and .vtu have "
                 "none)");
  mesh->add_option("--dump-stuck", dump_stuck, "when elimination gets stuck, write the surface it stopped at (.obj .off)");
  mesh->add_option("--sharp-angle", sharp_angle, "deviation from flat (degrees) above which an edge is sharp")
      ->check(CLI::Range(0.0, 180.0))->capture_default_str();
  mesh->add_option("--time-limit", params.elimination.time_limit_s,
                   "--planner greedy: give up elimination after this many seconds (0 = no limit)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  std::string planner = "search";
  mesh->add_option("--planner", planner,
                   "search: portfolio search over elimination orders (greedy, windowed backtracking, "
                   "conflict-directed restarts, beam, restarts) within the budget; "
                   "greedy: one greedy pass in the order rules' order (the paper's method)")
      ->check(CLI::IsMember({"search", "greedy"}))->capture_default_str();
  mesh->add_option("--plan-budget", params.planner.budget_s,
                   "budget of the search, in budget seconds: work counted deterministically "
                   "(feasibility tests weighted by chord length), about a wall-clock second each "
                   "on the reference machine (2 cores), so the plan never depends on machine speed "
                   "or load; the search stops earlier when its strategies are done")
      ->check(CLI::PositiveNumber)->capture_default_str();
  mesh->add_option("--improve-budget", params.planner.improve_budget_s,
                   "budget seconds (within --plan-budget) spent looking for a cheaper plan when "
                   "the first one needed backtracking; 0 = keep the first plan")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  mesh->add_option("--seed", params.planner.seed, "seed of the search's randomized restarts")
      ->capture_default_str();
  std::string side_rule = "cost";
  mesh->add_option("--side-rule", side_rule,
                   "cost: the side with fewer quads (fewer hexes) unless the other side is clearly "
                   "sharper (--side-threshold); heavier: the side with more sharp edges (paper 3.4)")
      ->check(CLI::IsMember({"cost", "heavier"}))->capture_default_str();
  mesh->add_option("--side-threshold", params.elimination.order.side_threshold,
                   "--side-rule cost: sharp-weight difference (0..1) that makes the larger side win")
      ->check(CLI::Range(0.0, 2.0))->capture_default_str();
  std::string method = "kremer";
  bool no_zero_volume = false, no_enclosed = false, no_concave = false, no_false_positive = false,
       no_concave_waits = false;
  mesh->add_option("--method", method, "elimination order: original (Müller-Hannemann) or kremer "
                                       "(Kremer et al. 2013 rules)")
      ->check(CLI::IsMember({"original", "kremer"}))->capture_default_str();
  mesh->add_flag("--no-zero-volume", no_zero_volume, "kremer: do not postpone zero-volume chords (4.1)");
  mesh->add_flag("--no-enclosed", no_enclosed, "kremer: do not make chords wait for enclosed chords (4.2)");
  mesh->add_flag("--no-concave", no_concave, "kremer: no concave chords / intrusion (5.1-5.3)");
  mesh->add_flag("--no-false-positive", no_false_positive,
                 "kremer: accept concave chords whose side region is not flat (5.4)");
  mesh->add_flag("--no-concave-waits", no_concave_waits,
                 "kremer: concave chords do not wait for enclosed non-flat chords (5.4)");
  bool no_stuck_fill = false;
  mesh->add_flag("--no-stuck-fill", no_stuck_fill,
                 "when elimination gets stuck, fail (exit 3) instead of filling the surface it "
                 "stopped at (up to --stuck-fill-quads quads) through a pit: one layer of hexes "
                 "under a few quads, whose inner surface is planned in turn");
  mesh->add_option("--stuck-fill-quads", params.terminal.max_quads,
                   "largest stuck surface (quads) the stuck fill is tried on; larger ones fail "
                   "as stuck (exit 3)")
      ->check(CLI::Range(1, 1000000))->capture_default_str();
  mesh->add_option("--stuck-fill-budget", params.terminal.total_budget_s,
                   "planning budget of the whole stuck fill, all pits and depths, in budget "
                   "seconds (see --plan-budget)")
      ->check(CLI::PositiveNumber)->capture_default_str();
  bool strict_intrusion = false;
  mesh->add_flag("--strict-intrusion", strict_intrusion,
                 "fail with invalid_intrusion (exit 3) when a concave step cannot be intruded, "
                 "instead of extruding it");
  bool no_intrusion_cover = false;
  mesh->add_flag("--no-intrusion-cover", no_intrusion_cover,
                 "--planner search: when intrusions are refused, do not rebuild the plan with "
                 "covering steps after its concave steps (default: rebuild it; when all its "
                 "intrusions go, mesh it too and keep the better mesh; screw2: 5 refused -> none, min / mean scaled "
                 "Jacobian 0.07 / 0.64 -> 0.28 / 0.80)");
  mesh->add_option("--intrusion-flip-rounds", params.intrusion_flip_rounds,
                   "when the plan meshed still has refused intrusions, replay it with those "
                   "concave steps eliminated towards their other side as convex steps (again "
                   "for what that plan refuses, up to N rounds), mesh it too when it refuses "
                   "fewer, and keep the better mesh (0 = off)")
      ->check(CLI::Range(0, 100))->capture_default_str();
  std::string pillow = "auto";
  bool no_untangle = false, no_optimize = false;
  mesh->add_option("--pillow", pillow,
                   "pillow layer under the boundary: auto = only around forced configurations "
                   "(hex corners the fixed boundary makes bad), all = whole boundary, none "
                   "(default: auto)")
      ->check(CLI::IsMember({"auto", "all", "none"}))->capture_default_str();
  mesh->add_option("--pillow-grow", params.pillow.grow,
                   "--pillow auto: rings of face neighbours added around the forced hexes to make "
                   "the local shrink set (0 = the forced hexes alone)")
      ->check(CLI::Range(0, 10))->capture_default_str();
  mesh->add_option("--pillow-whole-fraction", params.pillow.whole_fraction,
                   "--pillow auto: pillow the whole boundary instead when the local shrink set "
                   "holds at least this fraction of the hexes at the boundary (1 = always local)")
      ->check(CLI::Range(0.0, 1.0))->capture_default_str();
  mesh->add_option("--pillow-retry-band", params.pillow_retry_band,
                   "--pillow auto: when the optimized mesh's minimum scaled Jacobian is a corner "
                   "fixed by the boundary (no placement can raise it), pillow again counting the "
                   "corners up to this much above the minimum as forced, and keep the better mesh "
                   "(fewer hexes <= 0, or a minimum raised by more than the mean falls); 0 = no "
                   "retry")
      ->check(CLI::Range(0.0, 1.0))->capture_default_str();
  mesh->add_option("--repair-rounds", params.repair_rounds,
                   "while hexes stay <= 0 after untangling: rounds of a local pillow around them "
                   "and untangling again, each kept only when fewer hexes stay <= 0 (the last resort, "
                   "on the mesh kept after the other elimination orders), then, if hexes still stay "
                   "<= 0 and the first pillow was local, one round with the whole boundary "
                   "pillowed; 0 = none")
      ->check(CLI::Range(0, 20))->capture_default_str();
  mesh->add_option("--pillow-margin", params.pillow.target_margin,
                   "inward margin (0..1, unit normals) the pillow keeps at a boundary vertex's "
                   "copy by keeping hexes that are not forced out of the shrink set there: the "
                   "pillow hexes' corners at the copy cannot be better than about this; 0 = only "
                   "what a copy needs (1e-3); measured on real cuts: helps some, inverts others")
      ->check(CLI::Range(0.0, 1.0))->capture_default_str();
  mesh->add_flag("--no-untangle", no_untangle,
                 "keep the harmonic placement: no Winslow untangling (default: untangle)");
  mesh->add_flag("--no-optimize", no_optimize,
                 "skip the scaled-Jacobian optimization after untangling (default: optimize)");
  mesh->add_option("--polish-iterations", params.untangle.max_mean_inner,
                   "L-BFGS iterations of the mean polish in each optimization pass and of each run "
                   "of the final polish (raises the mean scaled Jacobian and never lowers the "
                   "minimum; 0 = skip both, for speed)")
      ->check(CLI::Range(0, 100000))->capture_default_str();
  mesh->add_option("--quality-passes", params.untangle.quality_passes,
                   "passes of the optimization (restarts, mean polish, max-min sweeps), each from "
                   "where the last left off, while one raises the minimum scaled Jacobian by 5e-3; "
                   "a pass that lowers the minimum, or the mean by more than it raises the minimum, "
                   "is undone (1 = one pass, faster)")
      ->check(CLI::Range(1, 100))->capture_default_str();
  mesh->add_option("--regularization", params.untangle.regularization,
                   "weight of the Winslow size term in the optimization passes: lower raises the "
                   "minimum scaled Jacobian on many meshes at some cost in the mean (screw2 with "
                   "--alternatives 0 and 0.003: 0.049 / 0.602 instead of 0.031 / 0.606; pierrot 0.362 / 0.784 instead "
                   "of 0.339 / 0.799)")
      ->check(CLI::Range(0.0, 1.0))->capture_default_str();
  mesh->add_option("--final-polish-runs", params.untangle.final_polish_runs,
                   "L-BFGS runs of the final mean polish after the passes (a log barrier keeps "
                   "every term above the minimum the passes reached, so it never lowers it), "
                   "before the mean sweeps (so not with --no-mean-sweep); a further run only when "
                   "the last did not converge; 0 = skip it, for speed")
      ->check(CLI::Range(0, 100))->capture_default_str();
  mesh->add_option("--final-polish-softmin", params.untangle.final_polish_softmin,
                   "sharpness of the final polish's mean term, a soft minimum over each hex's nine "
                   "scaled Jacobian terms, so that it lifts each hex's worst term (the hex's "
                   "scaled Jacobian); 0 = the passes' term, which lifts all nine alike")
      ->check(CLI::Range(0.0, 1000.0))->capture_default_str();
  mesh->add_option("--final-polish-rounds", params.untangle.final_polish_rounds,
                   "rounds of final polish and mean sweeps, each from where the last left off and "
                   "kept only if it raises the mean scaled Jacobian (1 instead of 2: screw2's mean 0.636 -> 0.621, "
                   "pierrot's 0.8069 -> 0.8058, 5-20% less time on small meshes)")
      ->check(CLI::Range(1, 100))->capture_default_str();
  bool no_mean_sweep = false;
  mesh->add_flag("--no-mean-sweep", no_mean_sweep,
                 "skip the local sweeps over every interior vertex that end the optimization "
                 "(they raise the mean scaled Jacobian: screw2 with --alternatives 0: 0.521 -> 0.606 with the final polish, "
                 "which runs only before them; a 10k-hex jittered "
                 "sphere untangles in 0.6 s without them, 1.1 s with)");
  std::string solver = "lbfgs";
  mesh->add_option("--solver", solver,
                   "untangling minimizer: lbfgs (L-BFGS) or newton (projected Newton with a "
                   "CHOLMOD sparse Cholesky; fewer, much costlier iterations) (default: lbfgs)")
      ->check(CLI::IsMember({"lbfgs", "newton"}))->capture_default_str();
  mesh->add_option("--alternatives", params.alternatives,
                   "other elimination orders tried when the mesh keeps hexes with scaled "
                   "Jacobian <= 0, or elimination gets stuck (not for lack of time) or an "
                   "intrusion is refused (the other side rule, the other method, both; each with "
                   "the whole plan budget); when concave steps had to be extruded because their "
                   "intrusion was refused, the other side rule (Kremer method) is tried too; the "
                   "best mesh is kept; 0 = only the given order")
      ->check(CLI::Range(0, 3))->capture_default_str();
  mesh->add_flag("--alternatives-always", params.alternatives_always,
                 "try the alternative orders even when the first mesh is valid and keep the one "
                 "with the largest minimum scaled Jacobian (slower)");
  int threads = 0;
  const std::string threads_help =
      "at most this many threads for the parallel loops (0 = one per core); the output is the "
      "same for any count";
  mesh->add_option("--threads", threads, threads_help)->check(CLI::Range(0, 1024))->capture_default_str();
  mesh->add_flag("-q,--quiet", quiet, "print only warnings and errors");

  std::string effort = "default";
  mesh->add_option("--effort", effort,
                   "fast: smaller budgets, fewer passes and retries; default; best: larger budgets, "
                   "more passes, every elimination order tried (options given explicitly win)")
      ->check(CLI::IsMember({"fast", "default", "best"}))->capture_default_str();
  // The everyday options; the others (tuning of the search, pillow, optimizer and retries) are
  // listed by --help-all only.
  const bool help_all = std::any_of(argv + 1, argv + argc, [](const char* a) {
    return std::string_view(a) == "--help-all";
  });
  mesh->set_help_all_flag("--help-all", "print every option, the expert ones too, and exit");
  for (CLI::Option* o : mesh->get_options()) {
    static const char* const kEveryday[] = {"help", "help-all", "output", "report", "html", "dump-stuck",
                                            "repair-fill",
                                            "repair-surface", "repaired-surface", "patch-sets",
                                            "sharp-angle", "effort", "plan-budget", "pillow",
                                            "threads", "quiet"};
    const auto& lnames = o->get_lnames();
    const bool everyday = o->get_positional() || std::any_of(std::begin(kEveryday), std::end(kEveryday), [&](const char* e) {
      return std::find(lnames.begin(), lnames.end(), e) != lnames.end();
    });
    if (!everyday) o->group(help_all ? "Expert options (see docs/cli.md)" : "");
  }

  auto* quality = app.add_subcommand("quality", "Report the quality of any hex mesh (.vtk .vtu .mesh .msh).");
  quality->add_option("MESH", in, "hex mesh file")->required();
  quality->add_option("--surface", surface, "also check that the mesh boundary equals this surface");
  quality->add_option("--json", json_out, "also write the report as JSON");
  quality->add_option("--html", html_out, "also write an HTML report: figures, histogram, worst hexes, 3D view");
  quality->add_option("--threads", threads, threads_help)->check(CLI::Range(0, 1024))->capture_default_str();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // A usage error: say what was wrong, then the usage of the (sub)command given.
    std::fprintf(stderr, "hexpeel: error: %s\n\n%s", e.what(), app.help().c_str());
    return 1;
  }
  std::unique_ptr<tbb::global_control> thread_limit;
  if (threads > 0)
    thread_limit = std::make_unique<tbb::global_control>(
        tbb::global_control::max_allowed_parallelism, static_cast<size_t>(threads));
  try {
    if (*check) return cmd_check(in, sharp_angle, json_out);
    if (*mesh) {
      params.search = planner == "search";
      params.terminal.enabled = !no_stuck_fill;
      params.elimination.order.side_rule = side_rule == "cost" ? SideRule::cost : SideRule::heavier;
      params.sharp_angle_deg = sharp_angle;
      params.repair_fill = repair_fill == "elimination" ? MeshParams::RepairFill::elimination
                           : repair_fill == "both"        ? MeshParams::RepairFill::both
                                                          : MeshParams::RepairFill::tets;
      params.pillow.mode = pillow == "all"    ? PillowMode::all
                           : pillow == "none" ? PillowMode::none
                                              : PillowMode::automatic;
      params.untangle.untangle = !no_untangle;
      params.untangle.optimize = !no_optimize;
      params.untangle.local_all = !no_mean_sweep;
      parse_untangle_solver(solver, params.untangle.solver);
      OrderParams& order = params.elimination.order;
      order.method = method == "original" ? Method::original : Method::kremer;
      order.zero_volume = !no_zero_volume;
      order.enclosed = !no_enclosed;
      order.concave = !no_concave;
      order.false_positive = !no_false_positive;
      order.concave_waits_for_enclosed = !no_concave_waits;
      params.reconstruction.fallback_to_extrusion = !strict_intrusion;
      params.intrusion_cover = !no_intrusion_cover;
      apply_effort(effort, *mesh, params);
      return cmd_mesh(in, out, report, dump_stuck, repaired_out, html_out, params, patch_sets, quiet);
    }
    if (*quality) return cmd_quality(in, surface, json_out, html_out);
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "hexpeel: error: out of memory\n");
    return 4;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hexpeel: %s\n", e.what());
    return 4;
  }
  return 1;
}
