// Line-oriented logging prefixed with the level, the wall-clock time and the component name.
#pragma once

#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>

namespace mocap {

enum class LogLevel { Debug, Info, Warn, Error };

// Writes "[WARN] [1732180000.123456] [tracker]: message" lines to stderr, one whole line per
// write so that lines of concurrent threads and processes never interleave. The threshold
// comes from MOCAP_LOG_LEVEL (debug, info, warn, error; default info).
class Logger {
 public:
  explicit Logger(std::string name) : name_(std::move(name)) {}

  template <class... Args>
  void debug(fmt::format_string<Args...> format, Args&&... args) const {
    log(LogLevel::Debug, format, std::forward<Args>(args)...);
  }
  template <class... Args>
  void info(fmt::format_string<Args...> format, Args&&... args) const {
    log(LogLevel::Info, format, std::forward<Args>(args)...);
  }
  template <class... Args>
  void warn(fmt::format_string<Args...> format, Args&&... args) const {
    log(LogLevel::Warn, format, std::forward<Args>(args)...);
  }
  template <class... Args>
  void error(fmt::format_string<Args...> format, Args&&... args) const {
    log(LogLevel::Error, format, std::forward<Args>(args)...);
  }

  template <class... Args>
  void log(LogLevel level, fmt::format_string<Args...> format, Args&&... args) const {
    if (enabled(level)) write(level, fmt::format(format, std::forward<Args>(args)...));
  }

  static bool enabled(LogLevel level);
  void write(LogLevel level, std::string_view message) const;
  const std::string& name() const { return name_; }

 private:
  std::string name_;
};

}  // namespace mocap
