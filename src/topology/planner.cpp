// Planner: portfolio search over dual cycle elimination orders (see planner.h).
//
// Works on one EliminationState with apply/undo (depth-first strategies) and on copies of it
// (beam search). States are identified by the Zobrist hash of the set of eliminated chords: the
// surface after eliminating a set does not depend on order or sides (DESIGN.md), so a state
// proven dead (no complete plan below it) stays dead whichever path reaches it.
//
// Plan cost = 1 + sum of |side| over all steps + a penalty per flat step (concave steps count
// like convex ones, see step_cost). The side of a convex step is the smaller one unless the other side's sharp
// weight is larger by side_threshold. Deterministic for a given seed: every choice is ordered by
// keys that end with the chord id, and the random noise comes from a seeded 64-bit generator.
#include "hexpeel/planner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <queue>
#include <unordered_map>
#include <unordered_set>

namespace hexpeel {
namespace {

using Clock = std::chrono::steady_clock;

/// splitmix64: a small, well-mixed generator with a defined output for every platform.
uint64_t splitmix(uint64_t& x) {
  uint64_t z = (x += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}
double unit(uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }

struct Step {
  int32_t chord = -1;
  int8_t side = 0;
  bool concave = false;
  bool flat = false;
  int32_t size = 0;  ///< quads on the chosen side
};

enum class Outcome { success, dead, aborted };

struct Search {
  Search(EliminationState& s, const PlannerParams& p, const Context& c)
      : st(s), params(p), ctx(c), policy(p.order), start(Clock::now()) {
    uint64_t x = 0x5eed0f5eedull;
    zob.resize(st.num_chords());
    for (auto& z : zob) z = splitmix(x);
    flat_penalty = p.flat_penalty > 0 ? p.flat_penalty : static_cast<double>(st.alive_quads());
  }

  EliminationState& st;
  const PlannerParams& params;
  const Context& ctx;
  OrderPolicy policy;
  Clock::time_point start;
  std::vector<uint64_t> zob;
  double flat_penalty;

  // the current path on `st`
  std::vector<Step> path;
  uint64_t hash = 0;
  double cost = 1.0;

  std::unordered_set<uint64_t> dead;
  PlannerStats stats;
  std::vector<Step> best;
  double best_cost = std::numeric_limits<double>::infinity();
  std::vector<Step> deepest_stuck;
  std::vector<double> activity;  ///< conflict activity per chord (empty outside conflict search)
  bool aborted = false;       ///< the current phase (or the whole budget) ran out
  double phase_end_s = 0.0;   ///< end of the current phase, in budget seconds (effort())

  /// The search's work so far: every feasibility test adds kTestWork plus its chord's length.
  /// Budgets and phases are measured in this, never in wall-clock time, so the plan found is the
  /// same on any machine, under any load and for any thread count.
  int64_t work = 0;
  static constexpr int64_t kTestWork = 18;
  /// Work per budget second: on the reference machine (2 cores, see README) a budget second took
  /// 0.75-1.1 s of planning on pierrot, screw2 and two 3-6k-quad real surfaces (least squares
  /// over those and 77 small surfaces: 5.2e-7 s per unit of chord length tested, 9.6e-6 s per
  /// test).
  static constexpr double kWorkPerSecond = 1.9e6;

  double elapsed() const { return std::chrono::duration<double>(Clock::now() - start).count(); }
  /// The work done so far in budget seconds.
  double effort() const { return static_cast<double>(work) / kWorkPerSecond; }
  bool out_of_time() {
    if (!aborted && effort() > std::min(phase_end_s, params.budget_s)) {
      aborted = true;
      stats.budget_exhausted = true;
    }
    return aborted;
  }
  /// Starts a phase that may use up to `fraction` of the whole budget from now; false when the
  /// budget is spent. Phases keep one strategy (a deep windowed search) from starving the others.
  bool begin_phase(double fraction) {
    const double now = effort();
    if (now >= params.budget_s) return false;
    aborted = false;
    phase_end_s = std::min(params.budget_s, now + fraction * params.budget_s);
    return true;
  }
  bool done() const { return st.alive_chords() <= 3; }
  /// Hexes the step adds, plus the flat penalty. A concave step's virtual hexes count as cost
  /// too: they come out again at intrusion, but rewarding them would steer the search into
  /// concave steps whose intrusions fail.
  double step_cost(const Step& s) const { return s.size + (s.flat ? flat_penalty : 0.0); }

  /// The step of a move: the policy's side (usable by construction) and its size.
  Step make_step(const Move& m, std::array<bool, 2> sides) const {
    Step s{m.chord, m.side, m.concave, m.flat, 0};
    if (s.side < 0 || !sides[s.side]) s.side = static_cast<int8_t>(sides[0] ? 0 : 1);
    s.size = st.side_size(m.chord, s.side);
    return s;
  }

  void push(const Step& s) {
    st.collapse(s.chord);
    path.push_back(s);
    hash ^= zob[s.chord];
    cost += step_cost(s);
    ++stats.nodes;
  }
  void pop() {
    st.undo();
    hash ^= zob[path.back().chord];
    cost -= step_cost(path.back());
    path.pop_back();
    ++stats.backtracks;
  }

  void record_plan(const char* strategy) {
    if (stats.plans_tried == 0) stats.first_plan_s = elapsed();
    ++stats.plans_tried;
    if (cost < best_cost) {
      best_cost = cost;
      best = path;
      stats.strategy = strategy;
    }
  }
  void record_stuck() {
    ++stats.stuck_events;
    if (path.size() > deepest_stuck.size()) deepest_stuck = path;
  }

  /// Shift of a chord's priority weight (same value for its quick and full keys): minus its
  /// conflict activity, plus seeded noise.
  double noise_of(int32_t chord, uint64_t noise_seed) const {
    const double shift = activity.empty() ? 0.0 : -activity[chord];
    if (noise_seed == 0) return shift;
    uint64_t x = noise_seed * 0x100000001b3ull ^ (hash + static_cast<uint64_t>(chord) * 0x9e3779b97f4a7c15ull);
    return shift + params.noise * unit(splitmix(x));
  }
  /// Feasible moves of the current state, best first, rated lazily: quick keys order the
  /// chords, feasibility and the full rating are computed only for chords that reach the front.
  /// Valid while the state is the one it was made on (apply + undo in between is fine).
  class MoveQueue {
   public:
    MoveQueue(Search& s, uint64_t noise_seed) : s_(s), noise_seed_(noise_seed), heap_(later) {
      for (int32_t c = 0; c < s.st.num_chords(); ++c)
        if (s.st.chord_alive(c)) {
          Move m = s.policy.quick(s.st, c);
          m.key[1] += s.noise_of(c, noise_seed);
          heap_.push({m, 0});
        }
    }
    std::optional<std::pair<Move, std::array<bool, 2>>> next() {
      while (!heap_.empty()) {
        auto [m, sides] = heap_.top();
        heap_.pop();
        if (sides == 0) {
          s_.work += kTestWork + s_.st.chord_length(m.chord);
          auto f = s_.st.feasibility(m.chord);
          if (!f.ok()) continue;
          Move full = s_.policy.full(s_.st, m.chord, f.sides);
          full.key[1] += s_.noise_of(m.chord, noise_seed_);
          heap_.push({full, static_cast<int8_t>(f.sides[0] | (f.sides[1] << 1))});
          continue;
        }
        return std::pair{m, std::array<bool, 2>{(sides & 1) != 0, (sides & 2) != 0}};
      }
      return std::nullopt;
    }

   private:
    using Entry = std::pair<Move, int8_t>;  // (move, usable sides bitmask; 0 = quick key)
    static bool later(const Entry& x, const Entry& y) {
      return std::tie(x.first.key, x.second) > std::tie(y.first.key, y.second);
    }
    Search& s_;
    uint64_t noise_seed_;
    std::priority_queue<Entry, std::vector<Entry>, bool (*)(const Entry&, const Entry&)> heap_;
  };

  std::optional<Step> next_move(uint64_t noise_seed) {
    auto m = MoveQueue(*this, noise_seed).next();
    if (!m) return std::nullopt;
    return make_step(m->first, m->second);
  }

  /// Greedy from the current state until done or stuck (the path stays applied).
  bool greedy(uint64_t noise_seed) {
    while (!done()) {
      if (out_of_time()) return false;
      std::optional<Step> s = next_move(noise_seed);
      if (!s) {
        record_stuck();
        dead.insert(hash);
        return false;
      }
      push(*s);
      ctx.report("planning", std::min(1.0, effort() / params.budget_s));
    }
    return true;
  }

  /// Complete depth-first search below the current state, in policy order, dead states skipped.
  Outcome dfs(int64_t& nodes_left, uint64_t noise_seed) {
    if (done()) return Outcome::success;
    if (out_of_time() || nodes_left <= 0) return Outcome::aborted;
    MoveQueue queue(*this, noise_seed);
    while (auto next = queue.next()) {
      const auto& [m, sides] = *next;
      if (dead.count(hash ^ zob[m.chord])) continue;
      push(make_step(m, sides));
      --nodes_left;
      Outcome o = dfs(nodes_left, noise_seed);
      if (o == Outcome::success) return o;
      uint64_t child = hash;
      pop();
      if (o == Outcome::aborted) return o;
      dead.insert(child);
    }
    dead.insert(hash);
    return Outcome::dead;
  }

  /// Greedy, then on a stuck state backtrack k = 1..window steps with a complete search below.
  /// Leaves the path applied on success; unwinds to `base` depth otherwise.
  bool greedy_with_window(uint64_t noise_seed, const char* strategy) {
    const size_t base = path.size();
    const int64_t stuck_before = stats.stuck_events;
    if (greedy(noise_seed)) {
      record_plan(stats.stuck_events == stuck_before && noise_seed == 0 ? "greedy" : strategy);
      return true;
    }
    const size_t stuck_depth = path.size();
    for (int k = 1; k <= params.window && !aborted; ++k) {
      if (stuck_depth < base + static_cast<size_t>(k)) break;
      while (path.size() > stuck_depth - k) pop();
      int64_t nodes = params.window_nodes;
      Outcome o = dfs(nodes, noise_seed);
      if (o == Outcome::success) {
        record_plan(strategy);
        return true;
      }
    }
    while (path.size() > base) pop();
    return false;
  }

  void unwind() {
    while (!path.empty()) pop();
  }

  /// Conflict-directed search, after the restarts of SAT solvers: a stuck descent adds activity
  /// to the chords still alive at the stuck state (they are what could not be eliminated), which
  /// raises their priority within their tier so that later descents eliminate them while they
  /// still can be. Each round first repairs the stuck state by a small windowed search, then
  /// restarts from the top with fresh priority noise. (Backjumping only part of the way was
  /// measured on pierrot and found nothing in the same time: the chords that must go early are
  /// decided far above the stuck state.) Leaves the path applied on success.
  bool conflict_search() {
    activity.assign(st.num_chords(), 0.0);
    const size_t base = path.size();
    double bump = params.conflict_bump;
    uint64_t seeder = params.seed ^ 0xc0ff1c7ull;
    const uint64_t root = hash;
    // A dead root (every move from it proven to lead nowhere) ends the search: no plan exists.
    for (int64_t round = 0; !out_of_time() && !dead.count(root); ++round) {
      const uint64_t noise_seed = round == 0 ? 0 : splitmix(seeder) | 1;
      if (greedy(noise_seed)) {
        record_plan("conflict");
        return true;
      }
      const size_t stuck_depth = path.size();
      for (int32_t c = 0; c < st.num_chords(); ++c)
        if (st.chord_alive(c)) activity[c] += bump;
      bump *= params.conflict_growth;
      for (int k = 1; k <= params.conflict_window && !aborted; ++k) {
        if (stuck_depth < base + static_cast<size_t>(k)) break;
        while (path.size() > stuck_depth - k) pop();
        int64_t nodes = params.conflict_window_nodes;
        if (dfs(nodes, noise_seed) == Outcome::success) {
          record_plan("conflict");
          return true;
        }
      }
      while (path.size() > base) pop();
      ++stats.conflict_rounds;
    }
    return false;
  }

  /// Beam search over partial plans scored by cost, on copies of the state.
  void beam() {
    struct Node {
      EliminationState state;
      std::vector<Step> steps;
      uint64_t hash;
      double cost;
    };
    std::vector<Node> level;
    level.push_back({st, {}, 0, 1.0});
    while (!level.empty()) {
      for (Node& n : level)
        if (n.state.alive_chords() <= 3) {
          if (stats.plans_tried == 0) stats.first_plan_s = elapsed();
          ++stats.plans_tried;
          if (n.cost < best_cost) {
            best_cost = n.cost;
            best = n.steps;
            stats.strategy = "beam";
          }
          return;
        }
      struct Cand {
        double score;
        std::array<double, 4> key;
        size_t parent;
        Step step;
        uint64_t hash;
      };
      std::unordered_map<uint64_t, Cand> cands;
      for (size_t i = 0; i < level.size(); ++i) {
        if (out_of_time()) return;
        // generate moves on the node's own state
        std::swap(st, level[i].state);
        std::swap(hash, level[i].hash);
        MoveQueue queue(*this, 0);
        int taken = 0;
        while (auto next = queue.next()) {
          const auto& [m, sides] = *next;
          uint64_t h2 = hash ^ zob[m.chord];
          if (dead.count(h2)) continue;
          Step s = make_step(m, sides);
          double score = level[i].cost + step_cost(s);
          auto it = cands.find(h2);
          if (it == cands.end() || std::tie(score, m.key) < std::tie(it->second.score, it->second.key))
            cands[h2] = {score, m.key, i, s, h2};
          if (++taken >= params.beam_moves) break;
        }
        std::swap(st, level[i].state);
        std::swap(hash, level[i].hash);
      }
      if (cands.empty()) return;  // every beam state stuck
      std::vector<Cand> top;
      for (auto& [h, c] : cands) top.push_back(c);
      std::sort(top.begin(), top.end(), [](const Cand& a, const Cand& b) {
        return std::tie(a.score, a.key, a.hash) < std::tie(b.score, b.key, b.hash);
      });
      if (top.size() > static_cast<size_t>(params.beam_width)) top.resize(params.beam_width);
      std::vector<Node> next;
      for (const Cand& c : top) {
        Node n{level[c.parent].state, level[c.parent].steps, c.hash, c.score};
        n.state.collapse(c.step.chord);
        n.steps.push_back(c.step);
        ++stats.nodes;
        next.push_back(std::move(n));
      }
      level = std::move(next);
      ctx.report("planning", std::min(1.0, effort() / params.budget_s));
    }
  }
};

}  // namespace

PlannerResult run_planner(EliminationState& state, const PlannerParams& params, const Context& ctx) {
  PlannerResult res;
  EliminationPlan& plan = res.plan;
  plan.status = check_simple_chords(state);
  if (!plan.status.ok()) return res;
  Search s(state, params, ctx);
  // 1. cost-guided greedy with windowed backtracking (at most 15% of the budget)
  s.begin_phase(0.15);
  if (s.greedy_with_window(0, "window")) s.unwind();
  // 2. no plan yet: conflict-directed search, with all the budget left
  if (s.best.empty() && s.begin_phase(1.0) && s.conflict_search()) s.unwind();
  // 3-4. A plan that needed rescuing (its tail came from backtracking, not from the priorities):
  // beam search and randomized restarts look for a cheaper one, within improve_budget_s.
  if (!s.best.empty() && params.improve && s.stats.stuck_events > 0) {
    const double improve_end = std::min(params.budget_s, s.effort() + params.improve_budget_s);
    auto begin = [&](double seconds) {
      seconds = std::min(seconds, improve_end - s.effort());
      return seconds > 0 && s.begin_phase(seconds / params.budget_s);
    };
    if (begin(0.3 * params.improve_budget_s)) s.beam();
    uint64_t seeder = params.seed;
    for (int r = 0; r < params.restarts; ++r) {
      if (!begin((improve_end - s.effort()) / (params.restarts - r))) break;
      uint64_t noise_seed = splitmix(seeder) | 1;
      if (s.greedy_with_window(noise_seed, "restart")) s.unwind();
    }
  }
  s.unwind();
  res.stats = s.stats;
  res.stats.states_remembered = static_cast<int64_t>(s.dead.size());
  res.stats.time_s = s.elapsed();
  res.stats.effort_s = s.effort();

  // Replay the chosen plan (or the deepest stuck path) on the state, recording the steps.
  const bool found = !s.best.empty() || (state.alive_chords() <= 3);
  const std::vector<Step>& replay = found ? s.best : s.deepest_stuck;
  plan.stats.predicted_hexes = 1;
  for (const Step& st : replay) {
    PlanStep ps = state.apply(st.chord, st.side);
    ps.concave = st.concave;
    ps.flat = st.flat;
    plan.stats.predicted_hexes += (st.concave ? -1 : 1) * static_cast<int64_t>(ps.side_quads.size());
    plan.stats.flat_steps += st.flat;
    plan.stats.concave_steps += st.concave;
    plan.steps.push_back(std::move(ps));
  }
  plan.stats.steps = static_cast<int32_t>(plan.steps.size());
  plan.stats.time_s = res.stats.time_s;
  if (!found) {
    plan.stuck = diagnose_stuck(state);
    std::string why = res.stats.budget_exhausted ? "the planning budget ran out" : "every order tried got stuck";
    plan.status = Status::error(
        StatusCode::stuck,
        "no elimination order found (" + why + "; " + std::to_string(res.stats.plans_tried) +
            " plans, " + std::to_string(res.stats.nodes) + " steps tried, " +
            std::to_string(res.stats.states_remembered) + " dead states). Deepest stop after " +
            std::to_string(plan.steps.size()) + " steps: " + plan.stuck.text);
    return res;
  }
  res.stats.best_cost = s.best_cost;
  std::vector<int32_t> ids;
  state.current_surface(&ids);
  plan.final_quads = ids;
  for (int32_t q : ids) plan.final_corners.push_back(state.corners(q));
  if (ids.size() != 6) plan.status = Status::error(StatusCode::internal_error, "planner ended without a cube");
  return res;
}

}  // namespace hexpeel
