// The host-facing side of a Lawicel / SLCAN USB–CAN adaptor (slcan.hpp describes the
// protocol), as the simulated PixArt box plays it on a pseudo-terminal: it answers the
// commands the host sends, keeps the channel's state (bitrate, open or closed, timestamps)
// and formats the bus's frames the way the adaptor sends them to the host.
//
// Commands end with '\r' (a '\n' is ignored, as some tools add it). Answers, as Lawicel
// adaptors give them:
//   C          close the channel                      "\r" (also when already closed)
//   S0..S8     bitrate 10 kbit/s .. 1 Mbit/s          "\r"; BELL while open
//   O, L       open (L: listen only)                  "\r"; BELL while open or before a bitrate
//   Z0, Z1     frame timestamps off / on              "\r"
//   V, N, F    version, serial number, status flags   "V1013\r", "NPXSM\r", "F00\r"
//   t, T, r, R transmit a frame                       "z\r" (t, r) or "Z\r" (T, R) while open;
//                                                     BELL while closed or malformed
// Anything else, or a command longer than 64 bytes, is refused with BELL ('\a').
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "common/can_io/can_frame.hpp"

namespace mocap::pixart {

struct SimulatedSlcanAdaptorStats {
  uint64_t commands = 0;     // commands answered, refused ones included
  uint64_t refused = 0;      // answered with BELL
  uint64_t transmitted = 0;  // frames the host sent to the bus (the box ignores them)
};

class SimulatedSlcanAdaptor {
 public:
  // Takes bytes the host wrote, in chunks of any size; returns the answers to the commands
  // they complete, in order ("" when they complete none).
  std::string feed(std::string_view bytes);

  // Whether frames from the bus go to the host now.
  bool is_open() const { return open_; }
  // The bitrate set by the last "S" command, bit/s; nullopt before one.
  std::optional<int> bitrate() const { return bitrate_; }
  // Whether "Z1" asked for timestamps on frames.
  bool timestamps() const { return timestamps_; }

  // `frame` as the adaptor sends it to the host: encode_slcan's text, with the adaptor's
  // millisecond-in-the-minute timestamp (4 hex digits) when timestamps are on.
  std::string frame_message(const can::CanFrame& frame, int64_t stamp_ns) const;

  const SimulatedSlcanAdaptorStats& stats() const { return stats_; }
  // Why the last refused command was refused, with the command: "S while the channel is open".
  const std::string& last_refusal() const { return last_refusal_; }

 private:
  std::string answer(std::string_view command);
  std::string refuse(std::string reason);

  std::string command_;    // the unfinished command
  bool overlong_ = false;  // inside a command that was too long, until its '\r'
  bool open_ = false;
  std::optional<int> bitrate_;
  bool timestamps_ = false;
  SimulatedSlcanAdaptorStats stats_;
  std::string last_refusal_;
};

}  // namespace mocap::pixart
