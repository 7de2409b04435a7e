#include "sim/pixart_box_sim/simulated_slcan_adaptor.hpp"

#include <array>
#include <cctype>
#include <utility>

#include <fmt/format.h>

#include "common/can_io/slcan.hpp"

namespace mocap::pixart {
namespace {

constexpr char kCarriageReturn = '\r';
constexpr char kLineFeed = '\n';
constexpr char kBell = '\a';
constexpr size_t kMaxCommandLength = 64;
// Lawicel's timestamps count milliseconds and wrap every minute.
constexpr int64_t kTimestampWrap_ms = 60000;

// Lawicel's "S<n>" bitrate codes (slcan.cpp uses the same table to send them).
constexpr std::array<int, 9> kBitrates{10000,  20000,  50000,  100000, 125000,
                                       250000, 500000, 800000, 1000000};

// The SlcanParser accepts a transmit command's syntax exactly when it is a valid frame.
bool is_valid_frame(std::string_view command) {
  can::SlcanParser parser;
  parser.feed(command);
  parser.feed(std::string_view("\r", 1));
  return parser.take_frames().size() == 1;
}

std::string printable(std::string_view text) {
  std::string shown;
  for (char c : text) {
    if (std::isprint(static_cast<unsigned char>(c))) {
      shown += c;
    } else {
      shown += fmt::format("\\x{:02X}", static_cast<unsigned char>(c));
    }
  }
  return shown;
}

}  // namespace

std::string SimulatedSlcanAdaptor::feed(std::string_view bytes) {
  std::string answers;
  for (char byte : bytes) {
    if (byte == kLineFeed) continue;
    if (byte != kCarriageReturn) {
      if (overlong_) continue;
      if (command_.size() < kMaxCommandLength) {
        command_ += byte;
      } else {
        overlong_ = true;
      }
      continue;
    }
    if (overlong_) {
      ++stats_.commands;
      answers += refuse(fmt::format("a command longer than {} bytes", kMaxCommandLength));
    } else if (!command_.empty()) {  // a bare '\r' is how hosts flush a half-sent command
      answers += answer(command_);
    }
    command_.clear();
    overlong_ = false;
  }
  return answers;
}

std::string SimulatedSlcanAdaptor::answer(std::string_view command) {
  ++stats_.commands;
  const std::string done(1, kCarriageReturn);
  const char type = command[0];
  const std::string_view argument = command.substr(1);
  switch (type) {
    case 'C':
      if (!argument.empty()) break;
      open_ = false;
      return done;
    case 'S': {
      if (argument.size() != 1 || argument[0] < '0' || argument[0] > '8') break;
      if (open_) return refuse("S while the channel is open");
      bitrate_ = kBitrates[static_cast<size_t>(argument[0] - '0')];
      return done;
    }
    case 'O':
    case 'L':
      if (!argument.empty()) break;
      if (open_) return refuse(fmt::format("{} while the channel is open", type));
      if (!bitrate_) return refuse(fmt::format("{} before a bitrate was set", type));
      open_ = true;
      return done;
    case 'Z':
      if (argument != "0" && argument != "1") break;
      timestamps_ = argument == "1";
      return done;
    case 'V':
      if (!argument.empty()) break;
      return "V1013" + done;
    case 'N':
      if (!argument.empty()) break;
      return "NPXSM" + done;
    case 'F':
      if (!argument.empty()) break;
      return "F00" + done;
    case 't':
    case 'r':
    case 'T':
    case 'R':
      if (!open_) return refuse("a frame to send while the channel is closed");
      if (!is_valid_frame(command)) break;
      ++stats_.transmitted;
      return std::string(1, type == 't' || type == 'r' ? 'z' : 'Z') + done;
    default:
      break;
  }
  return refuse(fmt::format("unknown or malformed command '{}'", printable(command)));
}

std::string SimulatedSlcanAdaptor::refuse(std::string reason) {
  ++stats_.refused;
  last_refusal_ = std::move(reason);
  return std::string(1, kBell);
}

std::string SimulatedSlcanAdaptor::frame_message(const can::CanFrame& frame,
                                                 int64_t stamp_ns) const {
  std::string message = can::encode_slcan(frame);
  if (timestamps_) {
    const int64_t ms =
        ((stamp_ns / 1000000) % kTimestampWrap_ms + kTimestampWrap_ms) % kTimestampWrap_ms;
    message.insert(message.size() - 1, fmt::format("{:04X}", ms));
  }
  return message;
}

}  // namespace mocap::pixart
