#include <mocap/logger.hpp>

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <string>

namespace mocap {
namespace {

LogLevel threshold_from_environment() {
  const char* value = std::getenv("MOCAP_LOG_LEVEL");
  std::string level = value == nullptr ? "" : value;
  if (level == "debug") return LogLevel::Debug;
  if (level == "warn") return LogLevel::Warn;
  if (level == "error") return LogLevel::Error;
  return LogLevel::Info;
}

std::string_view label(LogLevel level) {
  switch (level) {
    case LogLevel::Debug:
      return "DEBUG";
    case LogLevel::Info:
      return "INFO";
    case LogLevel::Warn:
      return "WARN";
    case LogLevel::Error:
      return "ERROR";
  }
  return "?";
}

}  // namespace

bool Logger::enabled(LogLevel level) {
  static const LogLevel threshold = threshold_from_environment();
  return level >= threshold;
}

void Logger::write(LogLevel level, std::string_view message) const {
  auto since_epoch = std::chrono::system_clock::now().time_since_epoch();
  auto micros = std::chrono::duration_cast<std::chrono::microseconds>(since_epoch).count();
  std::string line = fmt::format("[{}] [{}.{:06d}] [{}]: {}\n", label(level), micros / 1000000,
                                 micros % 1000000, name_, message);
  // One write() per line: lines from threads and processes sharing stderr never interleave.
  const char* data = line.data();
  size_t left = line.size();
  while (left > 0) {
    ssize_t written = ::write(STDERR_FILENO, data, left);
    if (written <= 0) break;
    data += written;
    left -= static_cast<size_t>(written);
  }
}

}  // namespace mocap
