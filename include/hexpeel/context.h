// Context: what a stage may use to talk to the outside world. The library itself prints nothing.
#pragma once

#include <functional>
#include <string_view>

namespace hexpeel {

enum class LogLevel { debug, info, warning };

struct Context {
  /// Optional log sink; stages report warnings (e.g. "surface was inward, flipped") here.
  std::function<void(LogLevel, std::string_view)> log;
  /// Optional progress callback: stage name and fraction done in [0, 1].
  std::function<void(std::string_view stage, double fraction)> progress;

  void warn(std::string_view msg) const { if (log) log(LogLevel::warning, msg); }
  void info(std::string_view msg) const { if (log) log(LogLevel::info, msg); }
  void report(std::string_view stage, double f) const { if (progress) progress(stage, f); }
};

}  // namespace hexpeel
