// Log files of can-utils' `candump -L` (also `candump -l`), one frame per line:
//   (1436509052.249713) can0 123#DEADBEEF
// a receive time in seconds since the Unix epoch, the interface, and the frame in candump's
// notation (to_string in can_frame.hpp). The bridge replays them; the PixArt box simulator
// writes them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "common/can_io/can_frame.hpp"

namespace mocap::can {

// A malformed line or an unreadable file; the message says which and why.
class CandumpError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct CandumpRecord {
  int64_t stamp_ns = 0;   // receive time, nanoseconds since the Unix epoch
  std::string interface;  // "can0", "vcan0", "slcan0"
  CanFrame frame;         // frame.stamp_ns == stamp_ns
};

// Parses one log line. Accepted frames: standard ("123#...", 3 hex digits) and extended
// ("12345678#...", 8 hex digits) ids; 0 to 8 data bytes in hex, optionally separated by '.'
// ("123#DE.AD"); remote requests "123#R" with an optional length digit ("123#R4"). Leading and
// trailing blanks and '\r' are ignored, and so is a direction flag "R" or "T" after the frame
// (candump -x). Throws CandumpError with the reason for anything else, notably CAN FD frames
// ("123##1..."), error frames (CAN_ERR_FLAG in an 8-digit id), a raw DLC suffix ("_9"), more
// than 8 bytes, odd hex digits, a missing or malformed "(seconds.fraction)" stamp.
CandumpRecord parse_candump_line(std::string_view line);

// The line candump -L writes for `record`, without newline: "(0001436509.249713) can0 123#DE".
// Seconds take at least 10 digits and the fraction 6 (microseconds, truncated), as candump
// prints them, so that canplayer and other tools read our logs. Throws std::invalid_argument
// for a negative stamp, an interface name that is empty or holds blanks, or a frame that
// validate_frame refuses.
std::string format_candump_line(const CandumpRecord& record);

// Reads a log line by line, so that hours of recording replay without loading them whole.
// Blank lines and lines starting with '#' (after blanks) are skipped.
class CandumpReader {
 public:
  // Throws CandumpError "PATH: cannot read the candump log: <strerror>" when the file cannot be
  // opened.
  explicit CandumpReader(std::string path);

  // The next record; nullopt at the end of the file. Throws CandumpError "PATH:LINE: reason"
  // for a malformed line and "PATH: cannot read the candump log: <strerror>" for a read error
  // (a directory, a failing disk).
  std::optional<CandumpRecord> next();
  // The number of the line next() returned last (1-based); 0 before the first.
  size_t line_number() const { return line_number_; }
  const std::string& path() const { return path_; }

 private:
  struct FileCloser {
    void operator()(std::FILE* file) const { std::fclose(file); }
  };
  struct LineFree {
    void operator()(char* line) const { std::free(line); }
  };

  std::string path_;
  std::unique_ptr<std::FILE, FileCloser> file_;
  std::unique_ptr<char, LineFree> line_buffer_;  // getline(3)'s buffer, grown as needed
  size_t line_capacity_ = 0;
  size_t line_number_ = 0;
};

// Every record of the log at `path`, in file order; errors as CandumpReader's.
std::vector<CandumpRecord> read_candump_file(const std::string& path);

}  // namespace mocap::can
