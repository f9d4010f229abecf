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

namespace hexpeel {

enum class Method : int8_t {
  original,  ///< Müller-Hannemann's weights (paper 3.4)
};

/// How the side is chosen once a chord is picked.
enum class SideRule : int8_t {
  heavier,   ///< the side with the larger sharp weight; ties -> fewer quads (paper 3.4)
};

struct OrderParams {
  Method method = Method::original;
  SideRule side_rule = SideRule::heavier;
};

struct Move {
  int32_t chord = -1;
  int8_t side = -1;      ///< 0 left, 1 right; -1 = not decided (quick keys)
  bool concave = false;  ///< to be reconstructed by intrusion
  bool flat = false;     ///< crosses no sharp edge
  std::array<double, 4> key{};  ///< lexicographic, smaller first; the last entry is the chord id
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
