#include "follower/dynamixel/dynamixel_bus.hpp"

#include <array>
#include <utility>

#include <fmt/format.h>

namespace mocap::dynamixel {
namespace {

using SteadyClock = std::chrono::steady_clock;

// A status packet without parameters: FF FF ID LEN ERROR CHK.
constexpr size_t kEmptyStatusLength = 6;
// 8 data bits, a start and a stop bit.
constexpr double kBitsPerByte = 10;

serial::SerialPortOptions port_options(const DynamixelBusOptions& options) {
  return {.baud_rate = options.baud_rate,
          .write_timeout = options.write_timeout,
          .discard_pending_input = true};
}

serial::SerialPort open_port(std::string device, const DynamixelBusOptions& options) {
  if (auto problem = options.problem()) {
    throw std::invalid_argument("DynamixelBusOptions::" + *problem);
  }
  return serial::SerialPort(std::move(device), port_options(options));
}

std::string prefix(uint8_t id, uint8_t instruction) {
  return fmt::format("servo {}, {}", id, instruction_name(instruction));
}

}  // namespace

std::optional<std::string> DynamixelBusOptions::problem() const {
  // The port's own fields have the same names: baud_rate, write_timeout.
  if (auto problem = port_options(*this).problem()) return problem;
  if (reply_timeout.count() < 0) {
    return fmt::format("reply_timeout: {} ms is below 0", reply_timeout.count());
  }
  if (retries < 0) return fmt::format("retries: {} is below 0", retries);
  if (return_delay.count() < 0) {
    return fmt::format("return_delay: {} us is below 0", return_delay.count());
  }
  if (status_return_level < 0 || status_return_level > 2) {
    return fmt::format("status_return_level: {} is not 0, 1 or 2", status_return_level);
  }
  return std::nullopt;
}

std::string_view to_string(BusErrorKind kind) {
  switch (kind) {
    case BusErrorKind::kTimeout:
      return "timeout";
    case BusErrorKind::kCorrupt:
      return "corrupt reply";
    case BusErrorKind::kServoError:
      return "servo error";
    case BusErrorKind::kPortGone:
      return "port gone";
  }
  return "unknown";
}

BusError::BusError(BusErrorKind kind, uint8_t id, uint8_t instruction, const std::string& message,
                   uint8_t servo_errors, std::vector<uint8_t> reply_data)
    : std::runtime_error(message),
      kind_(kind),
      id_(id),
      instruction_(instruction),
      servo_errors_(servo_errors),
      reply_data_(std::move(reply_data)) {}

DynamixelBus::DynamixelBus(std::string device, DynamixelBusOptions options)
    : options_(options), port_(open_port(std::move(device), options)) {}

uint8_t DynamixelBus::ping(uint8_t id) {
  const auto instruction = static_cast<uint8_t>(Instruction::kPing);
  if (id == kBroadcastId) {
    throw std::invalid_argument(
        "Dynamixel PING to the broadcast ID: Protocol 1.0 never answers it");
  }
  const std::optional<Packet> reply = transact(id, instruction, encode_ping(id), true, 0);
  if (reply->code != 0) ++stats_.servo_errors;
  return reply->code;
}

std::vector<uint8_t> DynamixelBus::read(uint8_t id, uint8_t address, uint8_t length) {
  const auto instruction = static_cast<uint8_t>(Instruction::kRead);
  if (id == kBroadcastId) {
    throw std::invalid_argument("Dynamixel READ from the broadcast ID: nobody would answer");
  }
  if (!answers(instruction, id)) {
    throw std::invalid_argument(
        "Dynamixel READ with status return level 0: the servos never answer it");
  }
  std::optional<Packet> reply =
      transact(id, instruction, encode_read(id, address, length), true, length);
  check_servo_errors(*reply, instruction);
  return std::move(reply->parameters);
}

uint8_t DynamixelBus::read_u8(uint8_t id, uint8_t address) { return read(id, address, 1)[0]; }

uint16_t DynamixelBus::read_u16(uint8_t id, uint8_t address) {
  const std::vector<uint8_t> bytes = read(id, address, 2);
  return static_cast<uint16_t>(bytes[0] | (bytes[1] << 8));
}

void DynamixelBus::write(uint8_t id, uint8_t address, std::span<const uint8_t> data) {
  const auto instruction = static_cast<uint8_t>(Instruction::kWrite);
  const std::optional<Packet> reply =
      transact(id, instruction, encode_write(id, address, data), answers(instruction, id), 0);
  if (reply) check_servo_errors(*reply, instruction);
}

void DynamixelBus::write_u8(uint8_t id, uint8_t address, uint8_t value) {
  const std::array<uint8_t, 1> data{value};
  write(id, address, data);
}

void DynamixelBus::write_u16(uint8_t id, uint8_t address, uint16_t value) {
  const std::array<uint8_t, 2> data{static_cast<uint8_t>(value & 0xFF),
                                    static_cast<uint8_t>(value >> 8)};
  write(id, address, data);
}

void DynamixelBus::sync_write(uint8_t address, uint8_t data_length,
                              std::span<const SyncWriteItem> items) {
  const auto instruction = static_cast<uint8_t>(Instruction::kSyncWrite);
  transact(kBroadcastId, instruction, encode_sync_write(address, data_length, items), false,
           std::nullopt);
}

bool DynamixelBus::answers(uint8_t instruction, uint8_t id) const {
  if (id == kBroadcastId) return false;
  if (instruction == static_cast<uint8_t>(Instruction::kPing)) return true;
  if (instruction == static_cast<uint8_t>(Instruction::kRead)) {
    return options_.status_return_level >= 1;
  }
  return options_.status_return_level >= 2;
}

void DynamixelBus::fail_port(uint8_t id, uint8_t instruction, const std::string& reason) {
  port_gone_ = true;
  gone_reason_ = reason;
  throw BusError(BusErrorKind::kPortGone, id, instruction,
                 fmt::format("{}: {}", prefix(id, instruction), reason));
}

void DynamixelBus::drain_input(uint8_t id, uint8_t instruction) {
  // Whatever arrived since the last transaction (a late answer to an attempt that timed out)
  // would otherwise pass for this one's answer.
  std::array<char, 256> buffer;
  try {
    while (port_.read(buffer.data(), buffer.size(), std::chrono::milliseconds(0)) > 0) {
    }
  } catch (const serial::SerialError& e) {
    fail_port(id, instruction, e.what());
  }
  parser_.reset();
}

void DynamixelBus::send(uint8_t id, uint8_t instruction, std::string_view packet) {
  try {
    port_.write_all(packet);
  } catch (const serial::SerialError& e) {
    fail_port(id, instruction, e.what());
  }
  ++stats_.packets_sent;
}

std::optional<Packet> DynamixelBus::transact(uint8_t id, uint8_t instruction,
                                             std::string_view packet, bool answered,
                                             std::optional<size_t> reply_parameters) {
  if (port_gone_) {
    throw BusError(BusErrorKind::kPortGone, id, instruction,
                   fmt::format("{}: {}", prefix(id, instruction), gone_reason_));
  }
  // The instruction and its answer cross the wire one after the other (half duplex).
  const size_t wire_bytes = packet.size() + kEmptyStatusLength + reply_parameters.value_or(0);
  const auto wire_time = std::chrono::microseconds(
      static_cast<int64_t>(wire_bytes * kBitsPerByte * 1e6 / options_.baud_rate));
  const auto budget = options_.reply_timeout + options_.return_delay + wire_time;

  const int attempts = options_.retries + 1;
  BusErrorKind failure = BusErrorKind::kTimeout;
  std::string problem;
  std::array<char, 512> buffer;
  for (int attempt = 0; attempt < attempts; ++attempt) {
    if (attempt > 0) ++stats_.retries;
    drain_input(id, instruction);
    send(id, instruction, packet);
    if (!answered) return std::nullopt;

    const uint64_t checksum_errors = parser_.stats().checksum_errors;
    const uint64_t length_errors = parser_.stats().length_errors;
    const auto deadline = SteadyClock::now() + budget;
    problem.clear();
    while (problem.empty()) {
      while (std::optional<Packet> reply = parser_.next()) {
        if (reply->id != id) {
          ++stats_.stray_packets;
          continue;
        }
        // A servo that refuses the instruction (range, instruction error) answers without
        // data; one that only reports its condition still answers in full.
        if (reply_parameters && reply->parameters.size() != *reply_parameters && reply->code == 0) {
          problem = fmt::format("{} parameters instead of {}", reply->parameters.size(),
                                *reply_parameters);
          break;
        }
        ++stats_.replies;
        return reply;
      }
      if (!problem.empty()) break;
      if (const uint64_t bad = parser_.stats().checksum_errors - checksum_errors; bad > 0) {
        stats_.checksum_errors += bad;
        problem = "bad checksum";
        break;
      }
      if (parser_.stats().length_errors != length_errors) {
        problem = "impossible length";
        break;
      }
      const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - SteadyClock::now());
      if (left.count() <= 0) break;
      size_t count = 0;
      try {
        count = port_.read(buffer.data(), buffer.size(), left);
      } catch (const serial::SerialError& e) {
        fail_port(id, instruction, e.what());
      }
      parser_.feed(std::string_view(buffer.data(), count));
    }
    if (problem.empty() && parser_.pending_bytes() > 0) {
      problem = fmt::format("a packet cut short ({} bytes)", parser_.pending_bytes());
    }
    if (problem.empty()) {
      ++stats_.timeouts;
      failure = BusErrorKind::kTimeout;
    } else {
      ++stats_.corrupt_replies;
      failure = BusErrorKind::kCorrupt;
    }
  }
  const auto budget_ms = std::chrono::ceil<std::chrono::milliseconds>(budget).count();
  if (failure == BusErrorKind::kTimeout) {
    throw BusError(failure, id, instruction,
                   fmt::format("{}: no reply within {} ms ({} attempts)", prefix(id, instruction),
                               budget_ms, attempts));
  }
  throw BusError(failure, id, instruction,
                 fmt::format("{}: corrupt reply: {} ({} attempts)", prefix(id, instruction),
                             problem, attempts));
}

void DynamixelBus::check_servo_errors(const Packet& reply, uint8_t instruction) {
  if (reply.code == 0) return;
  ++stats_.servo_errors;
  throw BusError(BusErrorKind::kServoError, reply.id, instruction,
                 fmt::format("{}: servo reports {} (error 0x{:02X})", prefix(reply.id, instruction),
                             describe_errors(reply.code), reply.code),
                 reply.code, reply.parameters);
}

}  // namespace mocap::dynamixel
