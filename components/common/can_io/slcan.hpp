// The Lawicel / SLCAN ASCII protocol that USB-CAN adaptors (CANable, CANUSB, most cheap
// "USB to CAN" sticks) speak over a serial line, so that the bridge can use such an adaptor
// directly, without slcand or a set-up script.
//
// Every message ends with '\r'. Frames travel as
//   tIIILDD..[SSSS]       standard (11-bit id, 3 hex digits)
//   TIIIIIIIILDD..[SSSS]  extended (29-bit id, 8 hex digits)
//   rIIIL[SSSS], RIIIIIIIIL[SSSS]  remote requests (length digit, no data)
// with L the length digit 0..8, DD the data bytes in hex and SSSS an optional timestamp
// (milliseconds 0..0xEA5F, sent by adaptors switched to "Z1" mode). Commands are answered
// with '\r' (done), '\a' (BELL, refused), or "z\r" / "Z\r" after a transmitted frame.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "common/can_io/adaptor_clock.hpp"
#include "common/can_io/can_frame.hpp"

namespace mocap::can {

// The frame as an adaptor expects it to send: "t1232DEAD\r", "T123456781AA\r", "r1230\r",
// uppercase hex, no timestamp. Throws std::invalid_argument for a frame that validate_frame
// refuses.
std::string encode_slcan(const CanFrame& frame);

// The commands that open the CAN channel at `bitrate` (bit/s), in order: "C\r" (close, in case
// a previous run left the channel open: the adaptor refuses "S" while open), "S<n>\r" (the
// bitrate), "Z1\r" (stamp received frames; an adaptor without timestamps refuses it with a
// BELL, and its frames are stamped when read) and "O\r" (open). Throws std::invalid_argument naming
// the supported bitrates for any other: 10000, 20000, 50000, 100000, 125000, 250000, 500000,
// 800000, 1000000.
std::vector<std::string> slcan_open_commands(int bitrate);
// The bitrates slcan_open_commands takes, ascending.
std::vector<int> slcan_bitrates();
// Closes the CAN channel: "C\r".
std::string slcan_close_command();

struct SlcanParserOptions {
  // A message longer than this without a terminator is garbage (the longest valid one,
  // an extended frame of 8 bytes with a timestamp, has 30 characters): it is dropped and the
  // rest of it, up to the next terminator, skipped, so that a stream of garbage (a wrong baud
  // rate, another device on the port) cannot make the parser's buffer grow.
  size_t max_message_length = 64;

  // Why these options cannot be used, naming the field ("max_message_length: 20; the longest
  // valid message has 30 characters"); nullopt when they can. SlcanParser's constructor
  // throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

struct SlcanStats {
  uint64_t frames = 0;           // frames decoded
  uint64_t errors = 0;           // messages rejected: malformed, unknown, or too long
  uint64_t bells = 0;            // '\a' replies: the adaptor refused a command
  uint64_t replies = 0;          // positive replies: empty messages ('\r'), "z", "Z"
  uint64_t discarded_bytes = 0;  // bytes of messages that were too long, terminators excluded
};

// Turns the bytes an SLCAN adaptor sends into frames. Bytes may come in chunks of any size:
// a message split across reads is completed by the next feed. Problems are counted in stats()
// and described by last_error(), never thrown, so that a noisy line cannot stop the input.
// Not thread-safe.
class SlcanParser {
 public:
  explicit SlcanParser(SlcanParserOptions options = {});

  // Parses `bytes`, read at `stamp_ns`. Frames completed by them wait in take_frames(),
  // stamped when the adaptor received them (AdaptorClock) if it stamps frames ("Z1" mode),
  // otherwise `stamp_ns`.
  void feed(std::string_view bytes, int64_t stamp_ns = 0);
  // The frames completed since the last call, oldest first.
  std::vector<CanFrame> take_frames();

  const SlcanStats& stats() const { return stats_; }
  // Why the last rejected message was rejected, with the message itself ("" if none was):
  // "DLC 9 is above 8 in 't1239...'".
  const std::string& last_error() const { return last_error_; }
  // Bytes of an unfinished message waiting for the rest; at most max_message_length.
  size_t pending_bytes() const { return message_.size(); }
  // Forgets an unfinished message, e.g. after the device was reopened. Keeps the counts.
  void reset();

 private:
  void end_message(int64_t stamp_ns);
  void reject(std::string reason);

  SlcanParserOptions options_;
  std::string message_;    // the unfinished message, without terminator
  bool skipping_ = false;  // inside a message that was too long, until its terminator
  std::vector<CanFrame> frames_;
  SlcanStats stats_;
  std::string last_error_;
  AdaptorClock adaptor_clock_;
};

}  // namespace mocap::can
