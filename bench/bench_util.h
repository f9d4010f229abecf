// Shared by the benchmark programs: run a job in a child process (so its peak memory can be
// measured and a crash cannot take the whole run down) and collect its JSON result.
#pragma once

#include <nlohmann/json.hpp>

#include <functional>
#include <string>

namespace hexpeel::bench {

struct Isolated {
  nlohmann::json result;     ///< what the job returned (empty object if it died)
  long peak_rss_kb = 0;      ///< child's maximum resident set size
  double wall_s = 0.0;
  std::string failure;       ///< non-empty when the child crashed or produced no result
};

/// Forks, runs `job` in the child, sends its JSON back through a pipe.
Isolated run_isolated(const std::function<nlohmann::json()>& job);

/// Least-squares slope of log(y) against log(x).
double fitted_exponent(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace hexpeel::bench
