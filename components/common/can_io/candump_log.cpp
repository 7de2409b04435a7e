#include "common/can_io/candump_log.hpp"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <limits>

#include <sys/types.h>

#include <fmt/format.h>

namespace mocap::can {
namespace {

constexpr int64_t kNanosecondsPerSecond = 1'000'000'000;
constexpr size_t kMaxFractionDigits = 9;          // nanoseconds
constexpr uint32_t kErrorFrameFlag = 0x20000000;  // CAN_ERR_FLAG of linux/can.h

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

std::string_view trim(std::string_view text) {
  while (!text.empty() && is_blank(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_blank(text.back())) text.remove_suffix(1);
  return text;
}

// Splits `text` at runs of blanks.
std::vector<std::string_view> split_fields(std::string_view text) {
  std::vector<std::string_view> fields;
  size_t position = 0;
  while (position < text.size()) {
    while (position < text.size() && is_blank(text[position])) ++position;
    const size_t start = position;
    while (position < text.size() && !is_blank(text[position])) ++position;
    if (position > start) fields.push_back(text.substr(start, position - start));
  }
  return fields;
}

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

bool all_digits(std::string_view text) {
  for (char c : text) {
    if (c < '0' || c > '9') return false;
  }
  return !text.empty();
}

// "1436509052.249713" -> nanoseconds.
int64_t parse_stamp(std::string_view text) {
  const size_t dot = text.find('.');
  const std::string_view seconds_text = text.substr(0, dot);
  const std::string_view fraction_text =
      dot == std::string_view::npos ? std::string_view{} : text.substr(dot + 1);
  if (!all_digits(seconds_text) || !all_digits(fraction_text)) {
    throw CandumpError(fmt::format("timestamp '({})' is not (seconds.fraction)", text));
  }
  if (fraction_text.size() > kMaxFractionDigits) {
    throw CandumpError(
        fmt::format("timestamp '({})' has more than {} fraction digits", text, kMaxFractionDigits));
  }
  constexpr int64_t kMaxSeconds = std::numeric_limits<int64_t>::max() / kNanosecondsPerSecond - 1;
  int64_t seconds = 0;
  for (char c : seconds_text) {
    seconds = seconds * 10 + (c - '0');
    if (seconds > kMaxSeconds)
      throw CandumpError(fmt::format("timestamp '({})' is too large", text));
  }
  int64_t fraction_ns = 0;
  for (size_t i = 0; i < kMaxFractionDigits; ++i) {
    fraction_ns = fraction_ns * 10 + (i < fraction_text.size() ? fraction_text[i] - '0' : 0);
  }
  return seconds * kNanosecondsPerSecond + fraction_ns;
}

// "123#DEADBEEF", "12345678#R", ... (see parse_candump_line).
CanFrame parse_frame(std::string_view text) {
  const size_t hash = text.find('#');
  if (hash == std::string_view::npos) {
    throw CandumpError(fmt::format("frame '{}' has no '#' between id and data", text));
  }
  const std::string_view id_text = text.substr(0, hash);
  std::string_view payload = text.substr(hash + 1);
  if (!payload.empty() && payload.front() == '#') {
    throw CandumpError(
        fmt::format("CAN FD frame '{}' ('##') is not supported: classic CAN only", text));
  }

  CanFrame frame;
  if (id_text.size() != 3 && id_text.size() != 8) {
    throw CandumpError(fmt::format(
        "id '{}' of frame '{}' must have 3 (standard) or 8 (extended) hex digits", id_text, text));
  }
  frame.extended = id_text.size() == 8;
  for (char c : id_text) {
    const int digit = hex_value(c);
    if (digit < 0) throw CandumpError(fmt::format("id '{}' is not hexadecimal", id_text));
    frame.id = frame.id << 4 | static_cast<uint32_t>(digit);
  }
  if (frame.extended && frame.id > kMaxExtendedId) {
    if (frame.id & kErrorFrameFlag) {
      throw CandumpError(
          fmt::format("error frame '{}' (CAN_ERR_FLAG set in the id) is not supported", text));
    }
    throw CandumpError(fmt::format("extended id {} is above {:08X}", id_text, kMaxExtendedId));
  }
  if (!frame.extended && frame.id > kMaxStandardId) {
    throw CandumpError(fmt::format("standard id {} is above {:03X}", id_text, kMaxStandardId));
  }

  if (!payload.empty() && (payload.front() == 'R' || payload.front() == 'r')) {
    frame.remote = true;
    payload.remove_prefix(1);
    if (payload.empty()) return frame;
    if (payload.size() == 1 && payload[0] >= '0' && payload[0] <= '8') {
      frame.length = static_cast<uint8_t>(payload[0] - '0');
      return frame;
    }
    throw CandumpError(
        fmt::format("remote frame '{}': only a length digit 0..8 may follow the 'R'", text));
  }

  for (size_t i = 0; i < payload.size();) {
    if (payload[i] == '.') {  // optional separator between bytes
      ++i;
      continue;
    }
    if (payload[i] == '_') {
      throw CandumpError(fmt::format("frame '{}': a raw DLC suffix ('_') is not supported", text));
    }
    const int high = hex_value(payload[i]);
    const int low = i + 1 < payload.size() ? hex_value(payload[i + 1]) : -1;
    if (high < 0 || low < 0) {
      throw CandumpError(
          fmt::format("data '{}' of frame '{}' is not pairs of hex digits", payload, text));
    }
    if (frame.length == kMaxDataLength) {
      throw CandumpError(
          fmt::format("frame '{}' has more than {} data bytes", text, kMaxDataLength));
    }
    frame.data[frame.length++] = static_cast<uint8_t>(high << 4 | low);
    i += 2;
  }
  return frame;
}

CandumpError read_error(const std::string& path, int error_number) {
  return CandumpError(
      fmt::format("{}: cannot read the candump log: {}", path, std::strerror(error_number)));
}

}  // namespace

CandumpRecord parse_candump_line(std::string_view line) {
  const std::string_view text = trim(line);
  if (text.empty()) throw CandumpError("empty line");
  if (text.front() != '(') {
    throw CandumpError(fmt::format("line '{}' does not start with '(seconds.fraction)'", text));
  }
  const size_t close = text.find(')');
  if (close == std::string_view::npos) {
    throw CandumpError(fmt::format("line '{}' has no ')' after the timestamp", text));
  }
  CandumpRecord record;
  record.stamp_ns = parse_stamp(text.substr(1, close - 1));

  const std::vector<std::string_view> fields = split_fields(text.substr(close + 1));
  if (fields.size() < 2) {
    throw CandumpError(fmt::format("line '{}' lacks the interface or the frame", text));
  }
  const bool direction_flag = fields.size() == 3 && (fields[2] == "R" || fields[2] == "T");
  if (fields.size() > 3 || (fields.size() == 3 && !direction_flag)) {
    throw CandumpError(
        fmt::format("unexpected '{}' after the frame in line '{}'", fields[2], text));
  }
  record.interface = fields[0];
  record.frame = parse_frame(fields[1]);
  record.frame.stamp_ns = record.stamp_ns;
  return record;
}

std::string format_candump_line(const CandumpRecord& record) {
  validate_frame(record.frame);
  if (record.stamp_ns < 0) {
    throw std::invalid_argument(fmt::format("candump stamp {} ns is before 1970", record.stamp_ns));
  }
  if (record.interface.empty() || record.interface.find_first_of(" \t\r\n") != std::string::npos) {
    throw std::invalid_argument(
        fmt::format("candump interface name '{}' is empty or holds blanks", record.interface));
  }
  return fmt::format("({:010}.{:06}) {} {}", record.stamp_ns / kNanosecondsPerSecond,
                     record.stamp_ns % kNanosecondsPerSecond / 1000, record.interface,
                     to_string(record.frame));
}

CandumpReader::CandumpReader(std::string path) : path_(std::move(path)) {
  file_.reset(std::fopen(path_.c_str(), "re"));  // 'e': O_CLOEXEC
  if (!file_) throw read_error(path_, errno);
}

std::optional<CandumpRecord> CandumpReader::next() {
  while (true) {
    char* buffer = line_buffer_.release();
    errno = 0;
    const ssize_t length = getline(&buffer, &line_capacity_, file_.get());
    const int error_number = errno;
    line_buffer_.reset(buffer);
    if (length < 0) {
      if (std::ferror(file_.get())) throw read_error(path_, error_number);
      return std::nullopt;
    }
    ++line_number_;
    const std::string_view line = trim({buffer, static_cast<size_t>(length)});
    if (line.empty() || line.front() == '#') continue;
    try {
      return parse_candump_line(line);
    } catch (const CandumpError& error) {
      throw CandumpError(fmt::format("{}:{}: {}", path_, line_number_, error.what()));
    }
  }
}

std::vector<CandumpRecord> read_candump_file(const std::string& path) {
  CandumpReader reader(path);
  std::vector<CandumpRecord> records;
  while (std::optional<CandumpRecord> record = reader.next()) records.push_back(std::move(*record));
  return records;
}

}  // namespace mocap::can
