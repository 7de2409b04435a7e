#include "common/can_io/slcan.hpp"

#include <array>
#include <optional>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

namespace mocap::can {
namespace {

constexpr char kCarriageReturn = '\r';
constexpr char kLineFeed = '\n';  // not Lawicel, but some adaptors and test tools add it
constexpr char kBell = '\a';
constexpr size_t kStandardIdDigits = 3;
constexpr size_t kExtendedIdDigits = 8;
constexpr size_t kTimestampDigits = 4;
// The adaptor counts milliseconds within a minute: 0 .. 59,999.
constexpr uint32_t kLastTimestamp = 0xEA5F;
// The longest valid message: 'T', the ID, the DLC, 8 data bytes and a timestamp.
constexpr size_t kLongestMessage = 1 + kExtendedIdDigits + 1 + 2 * 8 + kTimestampDigits;

// Lawicel's "S<n>" bitrate codes.
constexpr std::array<std::pair<int, char>, 9> kBitrateCodes{{{10000, '0'},
                                                             {20000, '1'},
                                                             {50000, '2'},
                                                             {100000, '3'},
                                                             {125000, '4'},
                                                             {250000, '5'},
                                                             {500000, '6'},
                                                             {800000, '7'},
                                                             {1000000, '8'}}};

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

// `message` fit for an error text: control and non-ASCII bytes as \xNN, cut after 40 bytes.
std::string quoted(std::string_view message) {
  constexpr size_t kMaxShown = 40;
  std::string text = "'";
  for (size_t i = 0; i < message.size() && i < kMaxShown; ++i) {
    const auto byte = static_cast<unsigned char>(message[i]);
    if (byte >= 0x20 && byte < 0x7F) {
      text += static_cast<char>(byte);
    } else {
      text += fmt::format("\\x{:02X}", byte);
    }
  }
  if (message.size() > kMaxShown) text += "...";
  return text + "'";
}

// Reads `digits` as one hex number (at most 8 digits); false if one is not a hex digit.
bool parse_hex(std::string_view digits, uint32_t& value) {
  value = 0;
  for (char c : digits) {
    const int digit = hex_value(c);
    if (digit < 0) return false;
    value = value << 4 | static_cast<uint32_t>(digit);
  }
  return true;
}

// Decodes a frame message ("t1232DEAD", without terminator) into `frame` and the adaptor's
// timestamp, if it has one, into `timestamp_ms`; or returns why not.
std::string decode_frame(std::string_view message, CanFrame& frame,
                         std::optional<uint32_t>& timestamp_ms) {
  const char type = message[0];
  frame.extended = type == 'T' || type == 'R';
  frame.remote = type == 'r' || type == 'R';
  const size_t id_digits = frame.extended ? kExtendedIdDigits : kStandardIdDigits;
  const size_t header_length = 1 + id_digits + 1;  // type, id, length digit
  if (message.size() < header_length) {
    return fmt::format("{} characters are too few for {} frame (at least {})", message.size(),
                       frame.extended ? "an extended" : "a standard", header_length);
  }
  if (!parse_hex(message.substr(1, id_digits), frame.id)) return "bad hex digit in the id";
  const uint32_t max_id = frame.extended ? kMaxExtendedId : kMaxStandardId;
  if (frame.id > max_id) return fmt::format("id 0x{:X} is above 0x{:X}", frame.id, max_id);

  const char length_digit = message[header_length - 1];
  const int length = hex_value(length_digit);
  if (length < 0) return fmt::format("bad length digit {}", quoted({&length_digit, 1}));
  if (length > kMaxDataLength) return fmt::format("DLC {} is above {}", length, kMaxDataLength);
  frame.length = static_cast<uint8_t>(length);

  const size_t data_digits = frame.remote ? 0 : 2 * static_cast<size_t>(length);
  const size_t rest = message.size() - header_length;
  if (rest != data_digits && rest != data_digits + kTimestampDigits) {
    return fmt::format("DLC {} needs {} characters after it (or {} with a timestamp), got {}",
                       length, data_digits, data_digits + kTimestampDigits, rest);
  }
  frame.data = {};
  for (size_t i = 0; i < data_digits / 2; ++i) {
    uint32_t byte = 0;
    if (!parse_hex(message.substr(header_length + 2 * i, 2), byte)) {
      return fmt::format("bad hex digit in data byte {}", i);
    }
    frame.data[i] = static_cast<uint8_t>(byte);
  }
  uint32_t timestamp = 0;
  if (rest > data_digits && !parse_hex(message.substr(header_length + data_digits), timestamp)) {
    return "bad hex digit in the timestamp";
  }
  if (timestamp > kLastTimestamp) {
    return fmt::format("timestamp 0x{:04X} is past a minute's last millisecond (0x{:04X})",
                       timestamp, kLastTimestamp);
  }
  timestamp_ms.reset();
  if (rest > data_digits) timestamp_ms = timestamp;
  return "";
}

}  // namespace

std::string encode_slcan(const CanFrame& frame) {
  validate_frame(frame);
  char type = frame.remote ? 'r' : 't';
  if (frame.extended) type = static_cast<char>(type - 'a' + 'A');
  std::string text = frame.extended ? fmt::format("{}{:08X}{}", type, frame.id, frame.length)
                                    : fmt::format("{}{:03X}{}", type, frame.id, frame.length);
  if (!frame.remote) {
    for (size_t i = 0; i < frame.length; ++i) text += fmt::format("{:02X}", frame.data[i]);
  }
  return text + kCarriageReturn;
}

std::vector<int> slcan_bitrates() {
  std::vector<int> bitrates;
  for (const auto& [bitrate, code] : kBitrateCodes) bitrates.push_back(bitrate);
  return bitrates;
}

std::vector<std::string> slcan_open_commands(int bitrate) {
  for (const auto& [supported, code] : kBitrateCodes) {
    if (supported == bitrate) {
      return {slcan_close_command(), std::string{'S', code, kCarriageReturn},
              std::string{'Z', '1', kCarriageReturn}, std::string{'O', kCarriageReturn}};
    }
  }
  std::string supported_list;
  for (const auto& [supported, code] : kBitrateCodes) {
    supported_list += (supported_list.empty() ? "" : ", ") + std::to_string(supported);
  }
  throw std::invalid_argument(
      fmt::format("unsupported SLCAN bitrate {} bit/s; supported: {}", bitrate, supported_list));
}

std::string slcan_close_command() { return std::string{'C', kCarriageReturn}; }

std::optional<std::string> SlcanParserOptions::problem() const {
  if (max_message_length < kLongestMessage) {
    return fmt::format("max_message_length: {}; the longest valid message has {} characters",
                       max_message_length, kLongestMessage);
  }
  return std::nullopt;
}

SlcanParser::SlcanParser(SlcanParserOptions options) : options_(options) {
  if (auto problem = options_.problem()) {
    throw std::invalid_argument("SlcanParserOptions::" + *problem);
  }
  message_.reserve(options_.max_message_length);
}

void SlcanParser::feed(std::string_view bytes, int64_t stamp_ns) {
  for (char byte : bytes) {
    // A line feed after a message's '\r' ("\r\n") is no message of its own.
    if (byte == kLineFeed && message_.empty() && !skipping_) continue;
    if (byte == kCarriageReturn || byte == kLineFeed || byte == kBell) {
      if (skipping_) {
        skipping_ = false;  // the too-long message ends here; it was counted when it started
      } else if (byte == kBell && !message_.empty()) {
        reject("message cut off by a BELL");
      } else if (byte != kBell) {
        end_message(stamp_ns);
      }
      message_.clear();
      if (byte == kBell) ++stats_.bells;
    } else if (skipping_) {
      ++stats_.discarded_bytes;
    } else if (message_.size() < options_.max_message_length) {
      message_ += byte;
    } else {
      reject(fmt::format("no terminator within {} bytes", options_.max_message_length));
      stats_.discarded_bytes += message_.size() + 1;
      message_.clear();
      skipping_ = true;
    }
  }
}

std::vector<CanFrame> SlcanParser::take_frames() {
  std::vector<CanFrame> frames;
  frames.swap(frames_);
  return frames;
}

void SlcanParser::reset() {
  message_.clear();
  skipping_ = false;
}

void SlcanParser::end_message(int64_t stamp_ns) {
  if (message_.empty() || message_ == "z" || message_ == "Z") {
    ++stats_.replies;
    return;
  }
  const char type = message_[0];
  if (type != 't' && type != 'T' && type != 'r' && type != 'R') {
    reject(fmt::format("unknown message type {}", quoted({&type, 1})));
    return;
  }
  CanFrame frame;
  std::optional<uint32_t> timestamp_ms;
  if (std::string error = decode_frame(message_, frame, timestamp_ms); !error.empty()) {
    reject(std::move(error));
    return;
  }
  frame.stamp_ns = timestamp_ms ? adaptor_clock_.host_time(*timestamp_ms, stamp_ns) : stamp_ns;
  frames_.push_back(frame);
  ++stats_.frames;
}

void SlcanParser::reject(std::string reason) {
  ++stats_.errors;
  last_error_ = fmt::format("{} in {}", reason, quoted(message_));
}

}  // namespace mocap::can
