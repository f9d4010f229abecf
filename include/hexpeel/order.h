// Order rules: how remaining chords are ranked for elimination and which side each one takes
// (paper 3.4 for the original method; Kremer et al. sections 4-5 extend it).
//
// A Move's key is compared lexicographically, smaller first. Ranking is two-phase so that only
// promising chords pay for expensive rules: `quick` gives a cheap key from the chord's weights
// that must never be larger than the key `full` gives the same chord later; `full` may look at
// side regions and other chords. Drivers (greedy, planner) pop by quick key, test feasibility,
// rate fully and re-queue when the full key is larger.
#pragma once

#include "hexpeel/elimination_state.h"

#include <array>
#include <cstdint>
#include <string_view>

namespace hexpeel {

enum class Method : int8_t {
  original,  ///< Müller-Hannemann's weights (paper 3.4)
  kremer,    ///< plus the rules of Kremer et al. sections 4-5, each switchable in OrderParams
};
std::string_view to_string(Method method);

/// How the side is chosen once a chord is picked.
enum class SideRule : int8_t {
  heavier,   ///< the side with the larger sharp weight; ties -> fewer quads (paper 3.4)
  cost,      ///< the side with fewer quads (fewer hexes) unless the other side's sharp weight is
             ///< larger by at least side_threshold; the chosen side's size also enters the key
};
std::string_view to_string(SideRule rule);

struct OrderParams {
  Method method = Method::kremer;
  SideRule side_rule = SideRule::cost;
  /// SideRule::cost: how much sharper (sharp weight difference, 0..1) the larger side must be to
  /// be chosen over the smaller one; > 1 = always the smaller side.
  double side_threshold = 0.5;
  /// SideRule::cost: weight of the chosen side's relative size (quads on it / quads left) in the
  /// key, so chords with small sides go first among equally sharp ones (>= 0).
  double size_weight = 2.0;
  // Kremer et al. rules (used only with Method::kremer; each can be switched off for ablation).
  /// 4.1: postpone a chord two of whose successive crossed edges bend by about 180 degrees in
  /// total (the layer would hold a zero-volume hex) while other candidates exist.
  bool zero_volume = true;
  /// |bend(e_i) + bend(e_i+1) - 180| at most this (degrees, in [0, 90]) counts as zero volume.
  double zero_volume_tolerance_deg = 30.0;
  /// 4.2: a chord whose elimination side contains a whole alive chord waits until that one is gone
  /// (a side that encloses nothing is preferred when both are usable).
  bool enclosed = true;
  /// 5.1-5.2: chords with a positive concavity weight on a usable side are eliminated first, by
  /// that weight, and reconstructed by intrusion; chords convex on both sides are postponed.
  bool concave = true;
  /// A side counts as concave when its concavity weight is at least this (> 0; the paper
  /// says "positive"; small weights are mostly one concave edge beside a convex layer, whose
  /// intrusion is invalid).
  double concave_min = 0.99;
  /// 5.2: "convex on both sides" means a convexity weight of at least this on both sides ([0, 1]).
  double both_convex_min = 0.5;
  /// 5.4 false positives: a concave chord's side region must be flat (no sharp edge between two
  /// of its quads), else the chord is rated as convex.
  bool false_positive = true;
  /// 5.4: a concave chord waits for every non-flat chord enclosed on its side.
  bool concave_waits_for_enclosed = true;
};

struct Move {
  int32_t chord = -1;
  int8_t side = -1;      ///< 0 left, 1 right; -1 = not decided (quick keys)
  bool concave = false;  ///< to be reconstructed by intrusion
  bool flat = false;     ///< crosses no sharp edge
  bool zero_volume = false;  ///< kremer 4.1: has a zero-volume configuration (postponed)
  bool waits = false;        ///< kremer 4.2 / 5.4: waits for a chord enclosed on its side
  /// Lexicographic, smaller first: {tier, -weight, length, chord id}. The tier is 0 or 1 (flat)
  /// for the original method; for kremer it also sums the postponements (order.cpp).
  std::array<double, 4> key{};
};

class OrderPolicy {
 public:
  explicit OrderPolicy(const OrderParams& params = {}) : params_(params) {}
  const OrderParams& params() const { return params_; }

  /// Cheap key from the chord's weights; a lower bound of full()'s key.
  Move quick(const EliminationState& state, int32_t chord) const;
  /// Full rating of a feasible chord; `sides` are its usable sides (at least one true).
  Move full(const EliminationState& state, int32_t chord, std::array<bool, 2> sides) const;

 private:
  OrderParams params_;
};

}  // namespace hexpeel
