// A Protocol 1.0 Dynamixel bus (protocol.hpp) on a serial device: a USB2Dynamixel or U2D2
// adaptor, or the pseudo-terminal of the simulated AX-12A chain. One instruction at a time:
// send it, wait for the addressed servo's status packet, check it.
//
//   DynamixelBus bus("/dev/ttyUSB0");
//   bus.write_u8(1, ax12::kTorqueEnable, 1);
//   bus.write_u16(1, ax12::kGoalPosition, 700);
//   uint16_t position = bus.read_u16(1, ax12::kPresentPosition);
//
// Every wait has a deadline, so a silent servo, a garbled line or an unplugged adaptor
// ends a call with a BusError, never a hang.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "common/serial_io/serial_port.hpp"
#include "follower/dynamixel/protocol.hpp"

namespace mocap::dynamixel {

enum class BusErrorKind {
  // No status packet from the servo before the deadline, in any attempt.
  kTimeout,
  // Something came back, but not a valid answer: a bad checksum, a packet cut short, a wrong
  // number of parameters.
  kCorrupt,
  // The servo answered with error bits set (BusError::servo_errors()).
  kServoError,
  // The serial device failed or went away (adaptor unplugged, simulator ended). Every later
  // call fails the same way at once; open a new DynamixelBus to reconnect.
  kPortGone,
};

// "timeout", "corrupt reply", "servo error", "port gone".
std::string_view to_string(BusErrorKind kind);

// Why a transaction failed. The message names the servo ID and the instruction:
// "servo 2, READ: no reply within 10 ms (3 attempts)",
// "servo 1, WRITE: servo reports overheating, overload (error 0x24)".
class BusError : public std::runtime_error {
 public:
  BusError(BusErrorKind kind, uint8_t id, uint8_t instruction, const std::string& message,
           uint8_t servo_errors = 0, std::vector<uint8_t> reply_data = {});

  BusErrorKind kind() const { return kind_; }
  uint8_t id() const { return id_; }
  uint8_t instruction() const { return instruction_; }
  // kServoError: the status packet's error bits (error_bit::...); 0 for the other kinds.
  uint8_t servo_errors() const { return servo_errors_; }
  // kServoError: the status packet's parameters, so that a READ still yields its data from a
  // servo that reports a condition (the temperature of an overheating servo).
  const std::vector<uint8_t>& reply_data() const { return reply_data_; }

 private:
  BusErrorKind kind_;
  uint8_t id_;
  uint8_t instruction_;
  uint8_t servo_errors_;
  std::vector<uint8_t> reply_data_;
};

struct DynamixelBusOptions {
  // Bits per second of the bus: the servos' baud rate register (AX-12A default 1 Mbit/s).
  int baud_rate = 1000000;
  // How long to wait for a status packet after the instruction went out, per attempt, on top
  // of the time the bytes take on the wire and return_delay.
  std::chrono::milliseconds reply_timeout{10};
  // Further attempts after a timeout or a corrupt reply. A servo error is never retried: the
  // servo heard the instruction, and answers the same way again.
  int retries = 2;
  // The servos' return delay time register, converted (2 us per unit; AX-12A default 250 =
  // 500 us): the servo waits this long before it answers.
  std::chrono::microseconds return_delay{500};
  // The servos' status return level: 2 answer every instruction, 1 only PING and READ, 0 only
  // PING. Instructions that get no answer are sent without waiting.
  int status_return_level = 2;
  // write_all gives up (kPortGone) when the device takes no bytes for this long.
  std::chrono::milliseconds write_timeout{200};

  // Why these options cannot be used, naming the field ("retries: -1 is below 0"); nullopt
  // when they can. DynamixelBus's constructor throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

struct DynamixelBusStats {
  uint64_t packets_sent = 0;     // instruction packets, retries included
  uint64_t replies = 0;          // valid status packets from the addressed servo
  uint64_t timeouts = 0;         // attempts that ended without a reply
  uint64_t corrupt_replies = 0;  // attempts that ended with a corrupt reply
  uint64_t checksum_errors = 0;  // status packets with a bad checksum
  uint64_t retries = 0;          // attempts after the first
  uint64_t servo_errors = 0;     // status packets with error bits
  uint64_t stray_packets = 0;    // valid packets from another ID (a late answer), ignored
};

// Not thread-safe: one transaction at a time, from one thread.
class DynamixelBus {
 public:
  // Opens `device` in raw mode at options.baud_rate. Throws serial::SerialError when it
  // cannot be opened, std::invalid_argument for options that cannot be used (an unsupported
  // baud rate, retries below 0, a status return level outside 0..2, a negative time).
  explicit DynamixelBus(std::string device, DynamixelBusOptions options = {});

  // Whether servo `id` answers. Returns its error bits (0 when all is well) rather than
  // throwing kServoError, since a servo that reports a condition is still there; throws
  // BusError for the other kinds (kTimeout: nobody with that ID). Protocol 1.0 has no
  // broadcast PING: std::invalid_argument for the broadcast ID.
  uint8_t ping(uint8_t id);

  // `length` bytes of the control table from `address`. Throws BusError, and
  // std::invalid_argument for the broadcast ID or with status return level 0 (never answered).
  std::vector<uint8_t> read(uint8_t id, uint8_t address, uint8_t length);
  uint8_t read_u8(uint8_t id, uint8_t address);
  uint16_t read_u16(uint8_t id, uint8_t address);

  // Writes `data` to the control table from `address`. To the broadcast ID: sent, not
  // answered. Throws BusError.
  void write(uint8_t id, uint8_t address, std::span<const uint8_t> data);
  void write_u8(uint8_t id, uint8_t address, uint8_t value);
  void write_u16(uint8_t id, uint8_t address, uint16_t value);

  // The same `data_length` bytes from `address` on several servos in one broadcast packet,
  // which no servo answers: nothing confirms it arrived. Throws std::invalid_argument for an
  // item of the wrong length, BusError (kPortGone) when the device is gone.
  void sync_write(uint8_t address, uint8_t data_length, std::span<const SyncWriteItem> items);

  const std::string& device() const { return port_.device(); }
  const DynamixelBusOptions& options() const { return options_; }
  const DynamixelBusStats& stats() const { return stats_; }
  // True once the device went away; every call then throws kPortGone.
  bool port_gone() const { return port_gone_; }

 private:
  // Sends `packet` and, when an answer is due, returns the valid status packet from `id`
  // (error bits included; the caller decides), after retries. nullopt when none is due.
  std::optional<Packet> transact(uint8_t id, uint8_t instruction, std::string_view packet,
                                 bool answered, std::optional<size_t> reply_parameters);
  void send(uint8_t id, uint8_t instruction, std::string_view packet);
  void drain_input(uint8_t id, uint8_t instruction);
  [[noreturn]] void fail_port(uint8_t id, uint8_t instruction, const std::string& reason);
  void check_servo_errors(const Packet& reply, uint8_t instruction);
  bool answers(uint8_t instruction, uint8_t id) const;

  DynamixelBusOptions options_;
  serial::SerialPort port_;
  PacketParser parser_;
  DynamixelBusStats stats_;
  bool port_gone_ = false;
  std::string gone_reason_;
};

}  // namespace mocap::dynamixel
