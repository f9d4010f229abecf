// Surface diagnosis for `hexpeel check`: validation (DESIGN.md "Input checking"), chords and
// their self-intersections (paper 2.1), sharp edges (paper 3.4, 5.1), as text and JSON.
//
// Dual cycle elimination needs every chord to be simple: a chord that passes through a quad twice
// bounds no sheet of hexes that could be peeled off, so such a surface is refused with the chords
// and quads named. Chords are still reported for surfaces that fail later checks (genus, parts,
// parity) whenever they are closed, manifold and consistently oriented, since they explain e.g.
// an odd quad count (an odd count forces a self-intersecting chord).
#include "hexpeel/diagnosis.h"

#include <cstdio>
#include <string>

namespace hexpeel {
namespace {

/// Listed chords / quads per message before "and N more".
constexpr size_t kListed = 10;

std::string join_ids(const std::vector<int32_t>& ids) {
  std::string s;
  for (size_t i = 0; i < ids.size() && i < kListed; ++i) s += (i ? ", " : "") + std::to_string(ids[i]);
  if (ids.size() > kListed) s += " and " + std::to_string(ids.size() - kListed) + " more";
  return s;
}

bool has_issue(const ValidationResult& v, StatusCode code) {
  for (const auto& is : v.issues)
    if (is.code == code) return true;
  return false;
}

std::string fmt(const char* format, double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, x);
  return buf;
}

}  // namespace

SurfaceDiagnosis diagnose_surface(const PolygonSoup& soup, double sharp_angle_deg,
                                  const Context& ctx, const ValidationParams& validation) {
  // Far from unit size, the checks run on the soup scaled by a power of two (exact), and the
  // surface returned is scaled back.
  if (const int k = scale_exponent(soup.points); k != 0) {
    PolygonSoup scaled = soup;
    scale_points(scaled.points, k);
    SurfaceDiagnosis d = diagnose_surface(scaled, sharp_angle_deg, ctx, validation);
    scale_points(d.validation.surface.points, -k);
    return d;
  }
  SurfaceDiagnosis d;
  d.sharp_angle_deg = sharp_angle_deg;
  d.validation = run_validation(soup, validation, ctx);
  d.status = d.validation.status;
  const QuadSurface& s = d.validation.surface;
  // Chord walks need every edge shared by two quads; a consistent orientation keeps a walk from
  // meeting itself reversed (on a non-orientable surface).
  if (s.quads.empty() || has_issue(d.validation, StatusCode::inconsistent_orientation)) return d;
  const QuadAdjacency adj = build_adjacency(s);
  for (int32_t o : adj.opposite)
    if (o < 0) return d;

  d.chords = find_chords(s, adj);
  d.chord_stats = chord_stats(d.chords);
  if (d.validation.status.ok()) d.edges = classify_edges(s, adj, sharp_angle_deg);

  if (d.chord_stats.self_intersecting > 0) {
    std::string list;
    size_t shown = 0;
    for (size_t c = 0; c < d.chords.chords.size(); ++c) {
      const Chord& ch = d.chords.chords[c];
      if (!ch.self_intersecting) continue;
      if (shown == kListed) {
        list += "; and " + std::to_string(d.chord_stats.self_intersecting - kListed) + " more";
        break;
      }
      ++shown;
      list += (list.empty() ? "" : "; ") + std::string("chord ") + std::to_string(c) +
              " (length " + std::to_string(ch.steps.size()) + ") crosses itself at quad" +
              (ch.crossings.size() == 1 ? " " : "s ") + join_ids(ch.crossings);
    }
    const std::string msg =
        std::to_string(d.chord_stats.self_intersecting) + " of " +
        std::to_string(d.chord_stats.count) + " chords " +
        (d.chord_stats.self_intersecting == 1 ? "intersects itself" : "intersect themselves") +
        ": " + list +
        ". Dual cycle elimination needs every chord to be simple (Müller-Hannemann 1999); the "
        "surface must be remeshed";
    if (d.status.ok()) d.status = Status::error(StatusCode::self_intersecting_chord, msg);
    if (d.status.code != StatusCode::self_intersecting_chord)
      ctx.warn(to_string(Status::error(StatusCode::self_intersecting_chord, msg)));
  }
  return d;
}

std::string mesh_path(const SurfaceDiagnosis& d) {
  if (d.status.ok()) return "dual cycle elimination (every chord is simple)";
  if (d.status.code != StatusCode::self_intersecting_chord)
    return "none (the surface is not valid input: " + std::string(to_string(d.status.code)) + ")";
  const ChordStats& cs = d.chord_stats;
  const bool odd = d.validation.surface.num_quads() % 2 != 0;
  return "none: " + std::to_string(cs.self_intersecting) + " of " + std::to_string(cs.count) +
         " chords cross themselves, at " + std::to_string(cs.self_crossings) + " quads" +
         (odd ? " (an odd quad count forces one)" : "") +
         "; hexpeel does not yet mesh such a surface with its quads kept (the shelling path is "
         "not implemented): remesh it so that every chord is simple, or let `hexpeel mesh "
         "--repair-surface` refine it (its boundary is then the refined surface)";
}

std::string to_text(const SurfaceDiagnosis& d) {
  const ValidationResult& v = d.validation;
  const ValidationStats& st = v.stats;
  std::string t = "status: " + to_string(d.status) + "\n";
  t += "input: " + std::to_string(st.points) + " vertices, " + std::to_string(st.faces) +
       " faces\n";
  if (!v.surface.quads.empty()) {
    t += "surface: " + std::to_string(v.surface.num_quads()) + " quads, " +
         std::to_string(v.surface.num_points()) + " vertices, " + std::to_string(st.edges) +
         " edges, " + std::to_string(st.components) +
         (st.components == 1 ? " part" : " parts") + ", genus " +
         (st.genus >= 0 ? std::to_string(st.genus) : std::string("not computed")) +
         (st.reoriented.empty() ? ""
                                : ", " + std::to_string(st.reoriented.size()) +
                                      " quads reversed to agree with their neighbours") +
         (st.flipped ? ", flipped to face outward" : "") + "\n";
  }
  for (const auto& is : v.issues)
    t += "error " + std::string(to_string(is.code)) + ": " + is.message + "\n";
  for (const auto& w : v.warnings) t += "warning: " + w + "\n";
  const ChordStats& cs = d.chord_stats;
  if (cs.count > 0) {
    t += "chords: " + std::to_string(cs.count) + ", length min " + std::to_string(cs.min_length) +
         " / mean " + fmt("%.1f", cs.mean_length) + " / max " + std::to_string(cs.max_length) +
         ", " + std::to_string(cs.self_intersecting) + " self-intersecting (at " +
         std::to_string(cs.self_crossings) + " quads)\n";
    for (size_t c = 0; c < d.chords.chords.size(); ++c) {
      const Chord& ch = d.chords.chords[c];
      if (ch.self_intersecting)
        t += "  chord " + std::to_string(c) + ": length " + std::to_string(ch.steps.size()) +
             ", crosses itself at quads " + join_ids(ch.crossings) + "\n";
    }
  }
  if (!d.edges.kind.empty())
    t += "edges at " + fmt("%g", d.sharp_angle_deg) + " deg: " +
         std::to_string(d.edges.sharp_convex) + " sharp convex, " +
         std::to_string(d.edges.sharp_concave) + " sharp concave, " +
         std::to_string(d.edges.flat) + " flat\n";
  return t;
}

nlohmann::json to_json(const SurfaceDiagnosis& d) {
  using nlohmann::json;
  const ValidationResult& v = d.validation;
  json j;
  j["status"] = {{"ok", d.status.ok()},
                 {"code", std::string(to_string(d.status.code))},
                 {"message", d.status.message}};
  json issues = json::array();
  for (const auto& is : v.issues)
    issues.push_back({{"code", std::string(to_string(is.code))},
                      {"message", is.message},
                      {"faces", is.faces},
                      {"vertices", is.vertices}});
  const ValidationStats& st = v.stats;
  j["validation"] = {{"issues", issues},
                     {"warnings", v.warnings},
                     {"input_vertices", st.points},
                     {"input_faces", st.faces},
                     {"quads", v.surface.num_quads()},
                     {"vertices", v.surface.num_points()},
                     {"edges", st.edges},
                     {"unused_vertices", st.unused_vertices},
                     {"components", st.components},
                     {"genus", st.genus},
                     {"reoriented", st.reoriented},
                     {"flipped", st.flipped}};
  json self = json::array();
  for (size_t c = 0; c < d.chords.chords.size(); ++c) {
    const Chord& ch = d.chords.chords[c];
    if (ch.self_intersecting)
      self.push_back({{"chord", c}, {"length", ch.steps.size()}, {"crossings", ch.crossings}});
  }
  const ChordStats& cs = d.chord_stats;
  j["chords"] = {{"count", cs.count},
                 {"min_length", cs.min_length},
                 {"mean_length", cs.mean_length},
                 {"max_length", cs.max_length},
                 {"self_intersecting", self}};
  j["edges"] = {{"sharp_angle_deg", d.sharp_angle_deg},
                {"classified", !d.edges.kind.empty()},
                {"sharp_convex", d.edges.sharp_convex},
                {"sharp_concave", d.edges.sharp_concave},
                {"flat", d.edges.flat}};
  j["chords"]["self_crossings"] = cs.self_crossings;
  j["path"] = mesh_path(d);
  return j;
}

}  // namespace hexpeel
