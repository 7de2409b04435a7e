#include "follower/dynamixel/protocol.hpp"

#include <array>
#include <stdexcept>

#include <fmt/format.h>

namespace mocap::dynamixel {
namespace {

constexpr uint8_t kHeaderByte = 0xFF;
// FF FF ID LEN: what must be there before LEN says how long the packet is.
constexpr size_t kHeaderLength = 4;

constexpr std::array<const char*, 8> kErrorNames{"input voltage", "angle limit", "overheating",
                                                 "range",         "checksum",    "overload",
                                                 "instruction",   "bit 7"};

uint8_t byte_at(std::string_view bytes, size_t index) { return static_cast<uint8_t>(bytes[index]); }

std::string with_data(uint8_t id, Instruction instruction, uint8_t address,
                      std::span<const uint8_t> data) {
  std::vector<uint8_t> parameters;
  parameters.reserve(data.size() + 1);
  parameters.push_back(address);
  parameters.insert(parameters.end(), data.begin(), data.end());
  return encode_packet(id, static_cast<uint8_t>(instruction), parameters);
}

}  // namespace

std::string instruction_name(uint8_t instruction) {
  switch (static_cast<Instruction>(instruction)) {
    case Instruction::kPing:
      return "PING";
    case Instruction::kRead:
      return "READ";
    case Instruction::kWrite:
      return "WRITE";
    case Instruction::kRegWrite:
      return "REG_WRITE";
    case Instruction::kAction:
      return "ACTION";
    case Instruction::kReset:
      return "RESET";
    case Instruction::kSyncWrite:
      return "SYNC_WRITE";
  }
  return fmt::format("instruction 0x{:02X}", instruction);
}

std::string describe_errors(uint8_t errors) {
  if (errors == 0) return "none";
  std::string names;
  for (size_t bit = 0; bit < kErrorNames.size(); ++bit) {
    if (!(errors & (1u << bit))) continue;
    if (!names.empty()) names += ", ";
    names += kErrorNames[bit];
  }
  return names;
}

uint8_t checksum(std::span<const uint8_t> body) {
  unsigned sum = 0;
  for (uint8_t byte : body) sum += byte;
  return static_cast<uint8_t>(~sum & 0xFF);
}

std::string encode_packet(uint8_t id, uint8_t code, std::span<const uint8_t> parameters) {
  if (parameters.size() > kMaxParameters) {
    throw std::invalid_argument(
        fmt::format("a Dynamixel packet holds at most {} parameters, not {}", kMaxParameters,
                    parameters.size()));
  }
  std::vector<uint8_t> body{id, static_cast<uint8_t>(parameters.size() + 2), code};
  body.insert(body.end(), parameters.begin(), parameters.end());
  std::string bytes(2, static_cast<char>(kHeaderByte));
  for (uint8_t byte : body) bytes += static_cast<char>(byte);
  bytes += static_cast<char>(checksum(body));
  return bytes;
}

std::string encode_ping(uint8_t id) {
  return encode_packet(id, static_cast<uint8_t>(Instruction::kPing), {});
}

std::string encode_read(uint8_t id, uint8_t address, uint8_t length) {
  const std::array<uint8_t, 2> parameters{address, length};
  return encode_packet(id, static_cast<uint8_t>(Instruction::kRead), parameters);
}

std::string encode_write(uint8_t id, uint8_t address, std::span<const uint8_t> data) {
  return with_data(id, Instruction::kWrite, address, data);
}

std::string encode_reg_write(uint8_t id, uint8_t address, std::span<const uint8_t> data) {
  return with_data(id, Instruction::kRegWrite, address, data);
}

std::string encode_action(uint8_t id) {
  return encode_packet(id, static_cast<uint8_t>(Instruction::kAction), {});
}

std::string encode_reset(uint8_t id) {
  return encode_packet(id, static_cast<uint8_t>(Instruction::kReset), {});
}

std::string encode_sync_write(uint8_t address, uint8_t data_length,
                              std::span<const SyncWriteItem> items) {
  std::vector<uint8_t> parameters{address, data_length};
  for (const SyncWriteItem& item : items) {
    if (item.id == kBroadcastId) {
      throw std::invalid_argument("SYNC_WRITE: an item for the broadcast ID");
    }
    if (item.data.size() != data_length) {
      throw std::invalid_argument(
          fmt::format("SYNC_WRITE of {} bytes: the item for servo {} has {} bytes", data_length,
                      item.id, item.data.size()));
    }
    parameters.push_back(item.id);
    parameters.insert(parameters.end(), item.data.begin(), item.data.end());
  }
  return encode_packet(kBroadcastId, static_cast<uint8_t>(Instruction::kSyncWrite), parameters);
}

std::string encode_status(uint8_t id, uint8_t errors, std::span<const uint8_t> parameters) {
  return encode_packet(id, errors, parameters);
}

// --- PacketParser --------------------------------------------------------------------------

std::optional<std::string> PacketParserOptions::problem() const {
  // LEN counts the instruction (or error) byte and the checksum.
  if (max_length < 2) {
    return fmt::format("max_length: {}; a packet's LEN is 2 at least", max_length);
  }
  return std::nullopt;
}

PacketParser::PacketParser(PacketParserOptions options) : options_(options) {
  if (auto problem = options_.problem()) {
    throw std::invalid_argument("PacketParserOptions::" + *problem);
  }
}

void PacketParser::feed(std::string_view bytes) {
  buffer_.append(bytes);
  parse();
}

std::optional<Packet> PacketParser::next() {
  if (next_packet_ >= packets_.size()) return std::nullopt;
  Packet packet = std::move(packets_[next_packet_++]);
  if (next_packet_ == packets_.size()) {
    packets_.clear();
    next_packet_ = 0;
  }
  return packet;
}

std::vector<Packet> PacketParser::take_packets() {
  std::vector<Packet> taken(
      std::make_move_iterator(packets_.begin() + static_cast<long>(next_packet_)),
      std::make_move_iterator(packets_.end()));
  packets_.clear();
  next_packet_ = 0;
  return taken;
}

void PacketParser::reset() {
  buffer_.clear();
  packets_.clear();
  next_packet_ = 0;
}

void PacketParser::discard(size_t count) {
  stats_.discarded_bytes += count;
  buffer_.erase(0, count);
}

void PacketParser::parse() {
  const std::string_view header("\xFF\xFF", 2);
  while (!buffer_.empty()) {
    const size_t start = buffer_.find(header);
    if (start == std::string::npos) {
      // A lone FF at the end may be the first half of the next header.
      const bool keep_last = byte_at(buffer_, buffer_.size() - 1) == kHeaderByte;
      discard(buffer_.size() - (keep_last ? 1 : 0));
      return;
    }
    discard(start);
    if (buffer_.size() < 3) return;
    if (byte_at(buffer_, 2) == kHeaderByte) {  // FF FF FF: no ID is 0xFF, so a fill byte
      discard(1);
      continue;
    }
    if (buffer_.size() < kHeaderLength) return;
    const size_t length = byte_at(buffer_, 3);
    if (length < 2 || length > options_.max_length) {
      ++stats_.length_errors;
      discard(2);
      continue;
    }
    const size_t total = kHeaderLength + length;
    if (buffer_.size() < total) return;
    std::vector<uint8_t> body(buffer_.begin() + 2, buffer_.begin() + static_cast<long>(total - 1));
    const bool checksum_ok = checksum(body) == byte_at(buffer_, total - 1);
    if (!checksum_ok) {
      ++stats_.checksum_errors;
      if (!options_.deliver_bad_checksums) {
        discard(2);
        continue;
      }
    }
    Packet packet{.id = body[0],
                  .code = body[2],
                  .parameters = std::vector<uint8_t>(body.begin() + 3, body.end()),
                  .checksum_ok = checksum_ok};
    packets_.push_back(std::move(packet));
    ++stats_.packets;
    buffer_.erase(0, total);
  }
}

}  // namespace mocap::dynamixel
