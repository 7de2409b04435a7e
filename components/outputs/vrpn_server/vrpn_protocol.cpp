#include "outputs/vrpn_server/vrpn_protocol.hpp"

#include <cstring>

#include <fmt/format.h>

namespace mocap::vrpn {
namespace {

constexpr std::string_view kMagic = "vrpn: ver. 07.38";
constexpr std::string_view kMajor = "vrpn: ver. 07.";
constexpr size_t kAlign = 8;

size_t padded(size_t length) { return (length + kAlign - 1) / kAlign * kAlign; }

void put_u32(std::string& out, uint32_t value) {
  for (int shift = 24; shift >= 0; shift -= 8) out += static_cast<char>((value >> shift) & 0xFF);
}

void put_i32(std::string& out, int32_t value) { put_u32(out, static_cast<uint32_t>(value)); }

void put_double(std::string& out, double value) {
  uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  for (int shift = 56; shift >= 0; shift -= 8) out += static_cast<char>((bits >> shift) & 0xFF);
}

uint32_t get_u32(std::string_view bytes, size_t at) {
  uint32_t value = 0;
  for (size_t i = 0; i < 4; ++i) value = value << 8 | static_cast<uint8_t>(bytes[at + i]);
  return value;
}

}  // namespace

std::string cookie() {
  std::string text = std::string(kMagic) + "  0";
  text.resize(kCookieSize, '\0');
  return text;
}

CookieCheck check_cookie(std::string_view bytes) {
  if (bytes.substr(0, kMajor.size()) != kMajor) return CookieCheck::NotVrpn;
  return bytes.substr(0, kMagic.size()) == kMagic ? CookieCheck::Same
                                                  : CookieCheck::OtherMinorVersion;
}

std::string encode(const Message& message) {
  std::string out;
  out.reserve(kHeaderSize + padded(message.payload.size()));
  put_u32(out, static_cast<uint32_t>(kHeaderSize + message.payload.size()));
  put_u32(out, message.seconds);
  put_u32(out, message.microseconds);
  put_i32(out, message.sender);
  put_i32(out, message.type);
  put_u32(out, message.sequence);
  out += message.payload;
  out.resize(kHeaderSize + padded(message.payload.size()), '\0');
  return out;
}

Message description(int32_t kind, int32_t id, std::string_view name) {
  Message message;
  message.sender = id;
  message.type = kind;
  put_u32(message.payload, static_cast<uint32_t>(name.size() + 1));
  message.payload += name;
  message.payload += '\0';
  return message;
}

std::optional<std::string> described_name(const Message& description) {
  const std::string& payload = description.payload;
  if (payload.size() < 5) return std::nullopt;
  const uint32_t length = get_u32(payload, 0);
  if (length == 0 || length > payload.size() - 4 || payload[4 + length - 1] != '\0') {
    return std::nullopt;
  }
  return payload.substr(4, length - 1);
}

std::string pos_quat_payload(int32_t sensor, const Eigen::Vector3d& position,
                             const Eigen::Quaterniond& orientation) {
  std::string out;
  put_i32(out, sensor);
  put_i32(out, sensor);
  for (int i = 0; i < 3; ++i) put_double(out, position[i]);
  for (double value : {orientation.x(), orientation.y(), orientation.z(), orientation.w()}) {
    put_double(out, value);
  }
  return out;
}

std::string velocity_payload(int32_t sensor, const Eigen::Vector3d& velocity,
                             const Eigen::Quaterniond& rotation_in_dt, double dt) {
  std::string out;
  put_i32(out, sensor);
  put_i32(out, sensor);
  for (int i = 0; i < 3; ++i) put_double(out, velocity[i]);
  for (double value :
       {rotation_in_dt.x(), rotation_in_dt.y(), rotation_in_dt.z(), rotation_in_dt.w()}) {
    put_double(out, value);
  }
  put_double(out, dt);
  return out;
}

std::optional<Message> MessageReader::next() {
  if (!error_.empty()) return std::nullopt;
  const std::string_view rest = std::string_view(buffer_).substr(read_);
  if (rest.size() < kHeaderSize) return std::nullopt;
  const uint32_t length = get_u32(rest, 0);
  if (length < kHeaderSize || length > max_message_bytes_) {
    error_ = fmt::format("a message of {} bytes (at least {}, at most {})", length, kHeaderSize,
                         max_message_bytes_);
    return std::nullopt;
  }
  const size_t whole = kHeaderSize + padded(length - kHeaderSize);
  if (rest.size() < whole) return std::nullopt;
  Message message;
  message.seconds = get_u32(rest, 4);
  message.microseconds = get_u32(rest, 8);
  message.sender = static_cast<int32_t>(get_u32(rest, 12));
  message.type = static_cast<int32_t>(get_u32(rest, 16));
  message.sequence = get_u32(rest, 20);
  message.payload = std::string(rest.substr(kHeaderSize, length - kHeaderSize));
  read_ += whole;
  if (read_ > 1 << 16 && read_ * 2 > buffer_.size()) {  // keep the buffer from growing
    buffer_.erase(0, read_);
    read_ = 0;
  }
  return message;
}

}  // namespace mocap::vrpn
