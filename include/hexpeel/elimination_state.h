// EliminationState: the undoable engine of dual cycle (chord) elimination (paper 3.1-3.2).
//
// It holds the intermediate surface (input quads keep their ids and corner order; only vertices
// merge), answers feasibility and side questions, collapses a chord and undoes the last collapse
// in O(chord length). The greedy driver (elimination.h) and the planner are built on it.
#pragma once

#include "hexpeel/chords.h"
#include "hexpeel/context.h"
#include "hexpeel/quad_surface.h"
#include "hexpeel/status.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace hexpeel {

/// Why a chord cannot be eliminated right now (paper 3.2 plus our bookkeeping limits).
enum class Infeasible : int8_t {
  none = 0,
  self_intersecting,   ///< the chord passes through a quad twice
  no_connected_side,   ///< neither side's quads form one edge-connected set
  degenerate_face,     ///< a remaining quad would get a repeated corner
  nonmanifold_edge,    ///< an edge would be used by other than two quads
  low_valence,         ///< a vertex would have fewer than three edges
  face_pair,           ///< two quads would share two vertices that are not an edge of both
  pinched_vertex,      ///< the quads around a merged vertex would form several fans
  euler,               ///< the collapse would change the Euler characteristic
  too_few_chords,      ///< only the cube's three chords are left
};
std::string_view to_string(Infeasible why);

/// Accumulated sharpness of an edge of the intermediate surface (weights add when edges merge).
struct EdgeWeight {
  int32_t sharp = 0;    ///< number of input sharp edges merged into this one
  int32_t convex = 0;   ///< ... of which convex
  int32_t concave = 0;  ///< ... of which concave
  double bend = 0.0;    ///< summed signed bend in degrees (>0 convex), for zero-volume tests
};

/// Per-side and flatness weights of a chord (paper 3.4 and 5.1), divided by its length.
struct ChordWeights {
  int32_t length = 0;
  std::array<double, 2> sharp{};    ///< [left, right]: sharp parallel edges / length
  std::array<double, 2> convex{};   ///< convex sharp parallel edges / length
  std::array<double, 2> concave{};  ///< concave sharp parallel edges / length
  int32_t crossing_sharp = 0;       ///< sharp edges the chord crosses; 0 = a flat chord
};

/// What reconstruction needs for one chord quad g of an eliminated chord: the quad h across g's
/// parallel edge on side s (local edge `es` of g) and the local edge j of h that g collapses into.
struct ChordQuadRecord {
  int32_t quad = -1;  ///< g
  int8_t es = 0;      ///< local edge of g parallel to the chord, on side s
  int32_t h = -1;     ///< quad across that edge (on side s, never a chord quad)
  int8_t j = 0;       ///< local edge of h shared with g before the collapse
};

struct PlanStep {
  int32_t chord = -1;                 ///< id in the input ChordSet
  int8_t side = 0;                    ///< 0 = left, 1 = right of the chord's walking direction
  bool concave = false;               ///< reconstructed by intrusion (Kremer 5.3)
  std::vector<int32_t> side_quads;    ///< quads on side s (sorted ids); |side| hexes
  std::vector<ChordQuadRecord> chord_quads;  ///< in chord walking order
  double priority = 0.0;              ///< the weight that chose this step
  bool flat = false;                  ///< a flat chord (eliminated only because nothing else was)
};

/// The intermediate surface, undoable. Not thread-safe (uses scratch buffers).
class EliminationState {
 public:
  /// `surface` must be valid (closed, manifold, genus 0, outward); `chords` its chord set;
  /// `edges` its edge classification.
  EliminationState(const QuadSurface& surface, const ChordSet& chords, const EdgeGeometry& edges);

  int32_t alive_quads() const { return alive_quads_; }
  int32_t alive_chords() const { return alive_chords_; }
  bool quad_alive(int32_t q) const { return quad_alive_[q] != 0; }
  bool chord_alive(int32_t c) const { return chord_len_[c] > 0; }
  int32_t chord_length(int32_t c) const { return chord_len_[c]; }
  int32_t num_chords() const { return static_cast<int32_t>(chords_->chords.size()); }
  /// The input chord set (chord_of tells which chords pass through a quad).
  const ChordSet& chord_set() const { return *chords_; }
  int32_t steps_applied() const { return static_cast<int32_t>(marks_.size()); }

  /// The current passages of chord c (input steps whose quad is alive), in walking order.
  void chord_steps(int32_t c, std::vector<ChordStep>& out) const;
  /// Current corners of quad q (merged vertex representatives, input corner order).
  Quad corners(int32_t q) const;
  /// Current opposite half-edge of half-edge 4q+k.
  int32_t opposite(int32_t he) const { return opp_[he]; }
  const EdgeWeight& edge_weight(int32_t he) const { return weight_[he]; }

  ChordWeights weights(int32_t c) const;

  /// Feasibility of eliminating chord c (3-connectivity by the local test of DESIGN.md, side
  /// connectivity), and which sides are usable: sides[s] is true when side s is edge-connected
  /// and its bookkeeping is possible.
  struct Feasibility {
    Infeasible why = Infeasible::none;
    std::array<bool, 2> sides{};
    bool ok() const { return why == Infeasible::none; }
  };
  Feasibility feasibility(int32_t c) const;

  /// Only the local polyhedrality test of collapsing chord c (no side or chord-count checks);
  /// exposed so tests can compare it with a brute-force 3-connectivity check.
  Infeasible collapse_check(int32_t c) const;

  /// Quads on side s of chord c (sorted ids), by a search that never enters the chord.
  void side_region(int32_t c, int side, std::vector<int32_t>& out) const;

  /// Which side of chord c every chord lies on: out[d] = 0 (left) or 1 (right) for an alive chord
  /// d != c that does not cross c (it then lies wholly on one side), -1 otherwise. Floods only
  /// the smaller side when the two sides partition the rest of the surface. O(min side + chords).
  void chord_sides(int32_t c, std::vector<int8_t>& out) const;

  /// Number of quads on side s of chord c. The first call after a change computes all chords'
  /// sizes at once by spanning-tree flux (O(quads + chord lengths)); later calls are O(1).
  int32_t side_size(int32_t c, int side) const;

  /// Collapses chord c, recording the step for side s (which must be usable). O(|c| + |side|).
  PlanStep apply(int32_t c, int side);
  /// Collapses chord c without recording a step (the surface does not depend on the side; search
  /// uses this and records only the plan it keeps). O(|c|).
  void collapse(int32_t c);
  /// Undoes the last apply. O(|c|).
  void undo();

  /// The current surface as a QuadSurface (points: positions of representatives) with the ids of
  /// the alive input quads in `quad_ids`.
  QuadSurface current_surface(std::vector<int32_t>* quad_ids = nullptr) const;

 private:
  int32_t find(int32_t v) const;
  int32_t valence(int32_t q, int corner) const;
  bool side_usable(const std::vector<ChordStep>& steps, int side) const;
  Infeasible collapse_test(const std::vector<ChordStep>& steps) const;
  void compute_side_sizes() const;
  void mark_chord_quads(const std::vector<ChordStep>& steps) const;
  bool is_marked(int32_t q) const { return cmark_[q] == cepoch_; }
  void set_opp(int32_t he, int32_t value);
  void set_weight(int32_t he, const EdgeWeight& w);
  void touch_quad(int32_t q);  ///< invalidates the cached weights of the chords through q

  const QuadSurface* surface_;  ///< the input surface (outlives the state)
  const ChordSet* chords_;      ///< its chords (outlives the state)
  std::vector<uint8_t> quad_alive_;   ///< per input quad
  std::vector<int32_t> chord_len_;    ///< alive passages per chord; 0 = eliminated
  std::vector<int32_t> opp_;          ///< opposite half-edge in the current surface
  std::vector<EdgeWeight> weight_;    ///< per half-edge, equal on both halves of an edge
  std::vector<int32_t> uf_parent_;    ///< union-find over input vertices (no path compression)
  std::vector<int8_t> uf_rank_;
  int32_t alive_quads_ = 0, alive_chords_ = 0;

  // Undo log: every write to opp_/weight_/uf_/quad_alive_/chord_len_ records the old value.
  struct LogEntry {
    enum Kind : int8_t { opp, weight, parent, rank, quad, chord } kind;
    int32_t index;
    int32_t old_int;
    EdgeWeight old_weight;
  };
  std::vector<LogEntry> log_;
  std::vector<size_t> marks_;  ///< log size before each applied step

  // scratch (mutable: queries are logically const)
  mutable std::vector<int32_t> stamp_;   ///< BFS visit marks (== epoch_)
  mutable int32_t epoch_ = 0;
  mutable std::vector<int32_t> cmark_;   ///< chord-quad marks (== cepoch_)
  mutable int32_t cepoch_ = 0;
  mutable std::vector<int32_t> local_parent_;  ///< collapse_test's trial merges (-1 = root)
  mutable std::vector<int32_t> vstamp_, rstamp_;  ///< collapse_test: vertex in VC / in R marks
  mutable std::vector<int32_t> qstamp_;           ///< collapse_test: quad seen marks
  mutable int32_t vepoch_ = 0, repoch_ = 0, qepoch_ = 0;
  mutable std::vector<int32_t> chord_hits_;    ///< collapse_test: crossings per other chord
  /// collapse_test's working lists, kept between calls to avoid allocations.
  struct CollapseScratch {
    std::vector<int32_t> touched, vc, faces_a, vc_faces_all, rset, rlive, around, at, par;
    std::vector<std::pair<int32_t, int>> vc_corner, x_corner;
    std::vector<Quad> newf;
    std::vector<std::pair<uint64_t, int32_t>> ekeys;
    std::vector<std::pair<int32_t, int32_t>> nbr, links, faces_at;
    std::vector<std::pair<int32_t, std::pair<int32_t, int>>> xs;
    std::vector<uint64_t> old_edges;
  };
  mutable CollapseScratch cs_;
  // weights() cache: valid while weights_version_[c] == chord_version_[c]
  std::vector<uint64_t> chord_version_;
  uint64_t version_counter_ = 1;
  mutable std::vector<uint64_t> weights_version_;
  mutable std::vector<ChordWeights> weights_cache_;
  mutable std::vector<ChordStep> scratch_steps_;
  mutable bool sizes_valid_ = false;                     ///< side_sizes_ match the surface
  mutable std::vector<std::array<int32_t, 2>> side_sizes_;  ///< per chord, [left, right]
  mutable std::vector<int32_t> tree_parent_, tree_size_;  ///< dual spanning tree (scratch)
};

}  // namespace hexpeel
