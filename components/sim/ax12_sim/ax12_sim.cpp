#include "sim/ax12_sim/ax12_sim.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include <fmt/format.h>

namespace mocap::dynamixel {
namespace {

using namespace ax12;

// Position units per second at 1 rpm: 360 degrees a minute over 300/1024 degrees a unit.
constexpr double kUnitsPerSecondPerRpm = 6.0 * 1024.0 / 300.0;
// The fault kOverheat puts the temperature this far above the limit.
constexpr double kOverheatMargin_c = 5;
// While locked, only torque enable .. torque limit (24..35) can be written.
constexpr size_t kLockedWritableEnd = kTorqueLimit + 2;

constexpr std::array<std::pair<Ax12Fault, std::string_view>, 5> kFaultNames{{
    {Ax12Fault::kNone, "none"},
    {Ax12Fault::kSilent, "silent"},
    {Ax12Fault::kCorruptReplies, "corrupt"},
    {Ax12Fault::kOverheat, "overheat"},
    {Ax12Fault::kOverload, "overload"},
}};

uint16_t u16_at(const std::array<uint8_t, kControlTableSize>& table, uint8_t address) {
  return get_u16(table, address);
}

void set_u16(std::array<uint8_t, kControlTableSize>& table, uint8_t address, uint16_t value) {
  const auto bytes = u16_bytes(value);
  table[address] = bytes[0];
  table[address + 1u] = bytes[1];
}

bool wheel_mode(const std::array<uint8_t, kControlTableSize>& table) {
  return u16_at(table, kCwAngleLimit) == 0 && u16_at(table, kCcwAngleLimit) == 0;
}

uint8_t clamp_to_byte(double value) {
  return static_cast<uint8_t>(std::clamp(std::lround(value), 0L, 255L));
}

}  // namespace

std::string_view to_string(Ax12Fault fault) {
  for (const auto& [value, name] : kFaultNames) {
    if (value == fault) return name;
  }
  return "unknown";
}

std::optional<Ax12Fault> parse_ax12_fault(std::string_view name) {
  for (const auto& [value, known] : kFaultNames) {
    if (known == name) return value;
  }
  return std::nullopt;
}

std::pair<uint8_t, Ax12Fault> parse_ax12_fault_spec(std::string_view text) {
  auto refuse = [&] {
    return std::invalid_argument(
        fmt::format("fault '{}': expected ID:FAULT with ID 0..253 and FAULT one of none, silent, "
                    "corrupt, overheat, overload (e.g. 2:overheat)",
                    text));
  };
  const size_t colon = text.find(':');
  if (colon == std::string_view::npos || colon == 0 || colon > 3) throw refuse();
  int id = 0;
  for (char c : text.substr(0, colon)) {
    if (c < '0' || c > '9') throw refuse();
    id = id * 10 + (c - '0');
  }
  const std::optional<Ax12Fault> fault = parse_ax12_fault(text.substr(colon + 1));
  if (id > kMaxServoId || !fault) throw refuse();
  return {static_cast<uint8_t>(id), *fault};
}

SimulatedAx12Chain::SimulatedAx12Chain(std::span<const uint8_t> ids,
                                       SimulatedAx12ChainOptions options)
    : options_(options), parser_(PacketParserOptions{.deliver_bad_checksums = true}) {
  std::set<uint8_t> seen;
  for (uint8_t id : ids) {
    if (id > kMaxServoId) {
      throw std::invalid_argument(
          fmt::format("simulated AX-12A: ID {} is above {}", id, kMaxServoId));
    }
    if (!seen.insert(id).second) {
      throw std::invalid_argument(fmt::format("simulated AX-12A: ID {} given twice", id));
    }
    Servo servo;
    servo.table = default_control_table(id);
    servo.temperature_c = options_.ambient_temperature_c;
    set_u16(servo.table, kGoalPosition, kCentrePosition);
    refresh(servo);
    servos_.push_back(servo);
  }
}

// --- The bus -------------------------------------------------------------------------------

std::string SimulatedAx12Chain::feed(std::string_view bytes, double time_s) {
  advance(time_s);
  parser_.feed(bytes);
  std::string replies;
  while (std::optional<Packet> packet = parser_.next()) replies += execute(*packet);
  stats_.ignored_bytes = parser_.stats().discarded_bytes;
  return replies;
}

std::string SimulatedAx12Chain::execute(const Packet& packet) {
  ++stats_.instructions;
  if (!packet.checksum_ok) ++stats_.checksum_errors;
  if (packet.id == kBroadcastId) {
    if (!packet.checksum_ok) return "";
    if (packet.code == static_cast<uint8_t>(Instruction::kSyncWrite)) {
      sync_write(packet.parameters);
      return "";
    }
    for (Servo& servo : servos_) {
      if (servo.fault == Ax12Fault::kSilent) continue;
      std::vector<uint8_t> unused;
      execute_one(servo, packet, unused);
      refresh(servo);
    }
    return "";
  }
  const std::vector<Servo*> targets = servos_with(packet.id);
  if (targets.empty()) ++stats_.unaddressed;
  // Several servos with one ID all answer, and garble each other's answers on a real bus.
  std::string replies;
  for (Servo* servo : targets) {
    if (servo->fault == Ax12Fault::kSilent) continue;
    // The level the instruction arrived under decides, so that the WRITE that changes it is
    // answered (or not) as the host that sent it expects.
    const uint8_t level = servo->table[kStatusReturnLevel];
    std::vector<uint8_t> data;
    const uint8_t errors =
        packet.checksum_ok ? execute_one(*servo, packet, data) : error_bit::kChecksum;
    refresh(*servo);
    replies += answer(*servo, packet.id, packet.code, level, errors, data);
  }
  return replies;
}

std::string SimulatedAx12Chain::answer(Servo& servo, uint8_t id, uint8_t instruction, uint8_t level,
                                       uint8_t errors, std::span<const uint8_t> data) {
  const bool due = instruction == static_cast<uint8_t>(Instruction::kPing) ||
                   (instruction == static_cast<uint8_t>(Instruction::kRead) && level >= 1) ||
                   level >= 2;
  if (!due) return "";
  std::string reply = encode_status(id, errors | condition_of(servo), data);
  if (servo.fault == Ax12Fault::kCorruptReplies)
    reply.back() = static_cast<char>(reply.back() ^ 0x5A);
  ++stats_.replies;
  return reply;
}

uint8_t SimulatedAx12Chain::execute_one(Servo& servo, const Packet& packet,
                                        std::vector<uint8_t>& data) {
  const std::vector<uint8_t>& parameters = packet.parameters;
  switch (static_cast<Instruction>(packet.code)) {
    case Instruction::kPing:
      return 0;
    case Instruction::kRead: {
      if (parameters.size() != 2) return error_bit::kInstruction;
      const size_t address = parameters[0], length = parameters[1];
      if (address + length > kControlTableSize) return error_bit::kRange;
      const auto first = servo.table.begin() + static_cast<long>(address);
      data.assign(first, first + static_cast<long>(length));
      return 0;
    }
    case Instruction::kWrite:
      if (parameters.size() < 2) return error_bit::kInstruction;
      return write_registers(servo, parameters[0], std::span(parameters).subspan(1), true);
    case Instruction::kRegWrite: {
      if (parameters.size() < 2) return error_bit::kInstruction;
      const uint8_t errors =
          write_registers(servo, parameters[0], std::span(parameters).subspan(1), false);
      if (errors & error_bit::kRange) return errors;
      servo.registered = parameters;
      servo.table[kRegistered] = 1;
      return errors;
    }
    case Instruction::kAction: {
      if (servo.registered.empty()) return error_bit::kInstruction;
      const std::vector<uint8_t> registered = std::move(servo.registered);
      servo.registered.clear();
      servo.table[kRegistered] = 0;
      return write_registers(servo, registered[0], std::span(registered).subspan(1), true);
    }
    case Instruction::kReset:
      reset(servo);
      return 0;
    case Instruction::kSyncWrite:  // only meaningful to the broadcast ID
      return error_bit::kInstruction;
  }
  return error_bit::kInstruction;
}

uint8_t SimulatedAx12Chain::write_registers(Servo& servo, uint8_t address,
                                            std::span<const uint8_t> data, bool apply) {
  const size_t end = address + data.size();
  if (end > kControlTableSize) return error_bit::kRange;
  if (servo.table[kLock] == 1 && (address < kTorqueEnable || end > kLockedWritableEnd)) {
    return error_bit::kRange;
  }
  auto candidate = servo.table;
  std::copy(data.begin(), data.end(), candidate.begin() + address);
  // Every register the write touches must be writable and end up in its range; a register
  // written only in part is checked with its other byte as it was.
  for (size_t at = address; at < end;) {
    const Register* reg = register_at(static_cast<uint8_t>(at));
    if (reg == nullptr || reg->read_only) return error_bit::kRange;
    const uint16_t value =
        reg->width == 2 ? u16_at(candidate, reg->address) : candidate[reg->address];
    if (value < reg->min_value || value > reg->max_value) return error_bit::kRange;
    at = reg->address + size_t{reg->width};
  }
  const bool wheel = wheel_mode(candidate);
  // The direction bit of the moving speed means something in wheel mode only.
  if (!wheel && u16_at(candidate, kMovingSpeed) > 1023) return error_bit::kRange;
  uint8_t errors = 0;
  const bool writes_goal = address < kGoalPosition + 2 && end > kGoalPosition;
  if (writes_goal && !wheel) {
    const uint16_t goal = u16_at(candidate, kGoalPosition);
    if (goal < u16_at(candidate, kCwAngleLimit) || goal > u16_at(candidate, kCcwAngleLimit)) {
      errors |= error_bit::kAngleLimit;
      candidate[kGoalPosition] = servo.table[kGoalPosition];
      candidate[kGoalPosition + 1] = servo.table[kGoalPosition + 1];
    }
  }
  if (apply) servo.table = candidate;
  return errors;
}

void SimulatedAx12Chain::sync_write(std::span<const uint8_t> parameters) {
  if (parameters.size() < 2) return;
  const uint8_t address = parameters[0];
  const size_t length = parameters[1];
  const size_t stride = length + 1;
  // A malformed SYNC_WRITE is ignored by every servo: none can tell where its share is.
  if (length == 0 || (parameters.size() - 2) % stride != 0) return;
  for (size_t offset = 2; offset < parameters.size(); offset += stride) {
    for (Servo* servo : servos_with(parameters[offset])) {
      if (servo->fault == Ax12Fault::kSilent) continue;
      write_registers(*servo, address, parameters.subspan(offset + 1, length), true);
      refresh(*servo);
    }
  }
}

void SimulatedAx12Chain::reset(Servo& servo) {
  servo.table = default_control_table(1);
  servo.registered.clear();
  // As at power-on, the goal is where the servo stands, so enabling the torque holds it.
  set_u16(servo.table, kGoalPosition,
          static_cast<uint16_t>(std::clamp(std::lround(servo.position), 0L, long{kMaxPosition})));
}

// --- Physics -------------------------------------------------------------------------------

void SimulatedAx12Chain::advance(double time_s) {
  if (!time_s_) {
    time_s_ = time_s;
    return;
  }
  const double dt = time_s - *time_s_;
  if (!(dt > 0)) return;
  time_s_ = time_s;
  for (Servo& servo : servos_) step(servo, dt);
}

void SimulatedAx12Chain::step(Servo& servo, double dt) {
  auto& table = servo.table;
  if (condition_of(servo) & table[kAlarmShutdown]) table[kTorqueEnable] = 0;
  const bool drives = table[kTorqueEnable] == 1 && u16_at(table, kTorqueLimit) > 0 &&
                      servo.fault != Ax12Fault::kOverload;
  const double max_rpm = kMaxSpeedRpmAt12V * options_.supply_voltage_v / 12.0;
  const uint16_t speed = u16_at(table, kMovingSpeed);
  const double commanded_rpm = std::min((speed & 0x3FF) * kRpmPerSpeedUnit, max_rpm);
  servo.speed_rpm = 0;
  if (drives && wheel_mode(table)) {
    servo.speed_rpm = (speed & kDirectionBit) ? -commanded_rpm : commanded_rpm;
    servo.position = std::fmod(servo.position + servo.speed_rpm * kUnitsPerSecondPerRpm * dt, 1024);
    if (servo.position < 0) servo.position += 1024;
  } else if (drives) {
    const double rpm = (speed & 0x3FF) == 0 ? max_rpm : commanded_rpm;
    const double distance = u16_at(table, kGoalPosition) - servo.position;
    const double reach = rpm * kUnitsPerSecondPerRpm * dt;
    if (std::abs(distance) <= reach) {
      servo.position += distance;
    } else {
      servo.position += std::copysign(reach, distance);
      servo.speed_rpm = std::copysign(rpm, distance);
    }
  }
  const double load = servo.fault == Ax12Fault::kOverload
                          ? 1.0
                          : options_.load_at_full_speed * servo.speed_rpm / kMaxSpeedRpmAt12V;
  const double settled =
      options_.ambient_temperature_c + options_.heating_at_full_load_c * std::abs(load);
  servo.temperature_c +=
      (settled - servo.temperature_c) * (1 - std::exp(-dt / options_.thermal_time_constant_s));
  refresh(servo);
}

void SimulatedAx12Chain::refresh(Servo& servo) {
  auto& table = servo.table;
  if (servo.fault == Ax12Fault::kOverheat) {
    servo.temperature_c = table[kTemperatureLimit] + kOverheatMargin_c;
  }
  if (condition_of(servo) & table[kAlarmShutdown]) table[kTorqueEnable] = 0;
  if (table[kTorqueEnable] == 0) servo.speed_rpm = 0;
  const auto present =
      static_cast<uint16_t>(std::clamp(std::lround(servo.position), 0L, long{kMaxPosition}));
  set_u16(table, kPresentPosition, present);
  set_u16(table, kPresentSpeed,
          to_direction_bit(static_cast<int>(std::lround(servo.speed_rpm / kRpmPerSpeedUnit))));
  int load = 0;
  if (servo.fault == Ax12Fault::kOverload) {
    load = u16_at(table, kGoalPosition) < present ? -1023 : 1023;
  } else {
    load = static_cast<int>(
        std::lround(1023 * options_.load_at_full_speed * servo.speed_rpm / kMaxSpeedRpmAt12V));
  }
  set_u16(table, kPresentLoad, to_direction_bit(load));
  table[kPresentVoltage] = clamp_to_byte(options_.supply_voltage_v * 10);
  table[kPresentTemperature] = clamp_to_byte(servo.temperature_c);
  const bool drives = table[kTorqueEnable] == 1 && u16_at(table, kTorqueLimit) > 0 &&
                      servo.fault != Ax12Fault::kOverload;
  const bool moving =
      drives &&
      (wheel_mode(table) ? servo.speed_rpm != 0 : servo.position != u16_at(table, kGoalPosition));
  table[kMoving] = moving ? 1 : 0;
}

uint8_t SimulatedAx12Chain::condition_of(const Servo& servo) const {
  uint8_t errors = 0;
  const double decivolts = options_.supply_voltage_v * 10;
  if (decivolts < servo.table[kMinVoltageLimit] || decivolts > servo.table[kMaxVoltageLimit]) {
    errors |= error_bit::kInputVoltage;
  }
  if (std::lround(servo.temperature_c) > servo.table[kTemperatureLimit]) {
    errors |= error_bit::kOverheating;
  }
  if (servo.fault == Ax12Fault::kOverload) errors |= error_bit::kOverload;
  return errors;
}

// --- Set-up and inspection -----------------------------------------------------------------

std::vector<SimulatedAx12Chain::Servo*> SimulatedAx12Chain::servos_with(uint8_t id) {
  std::vector<Servo*> found;
  for (Servo& servo : servos_) {
    if (servo.table[kId] == id) found.push_back(&servo);
  }
  return found;
}

SimulatedAx12Chain::Servo& SimulatedAx12Chain::servo(uint8_t id) {
  return const_cast<Servo&>(std::as_const(*this).servo(id));
}

const SimulatedAx12Chain::Servo& SimulatedAx12Chain::servo(uint8_t id) const {
  for (const Servo& servo : servos_) {
    if (servo.table[kId] == id) return servo;
  }
  throw std::out_of_range(fmt::format("simulated AX-12A chain: no servo with ID {}", id));
}

bool SimulatedAx12Chain::has_servo(uint8_t id) const {
  return std::any_of(servos_.begin(), servos_.end(),
                     [id](const Servo& servo) { return servo.table[kId] == id; });
}

std::vector<uint8_t> SimulatedAx12Chain::ids() const {
  std::vector<uint8_t> ids;
  for (const Servo& servo : servos_) ids.push_back(servo.table[kId]);
  return ids;
}

uint8_t SimulatedAx12Chain::register_u8(uint8_t id, uint8_t address) const {
  if (address >= kControlTableSize) {
    throw std::out_of_range(fmt::format("AX-12A control table address {}", address));
  }
  return servo(id).table[address];
}

uint16_t SimulatedAx12Chain::register_u16(uint8_t id, uint8_t address) const {
  if (address + 1u >= kControlTableSize) {
    throw std::out_of_range(fmt::format("AX-12A control table address {}", address));
  }
  return u16_at(servo(id).table, address);
}

double SimulatedAx12Chain::position(uint8_t id) const { return servo(id).position; }

void SimulatedAx12Chain::set_position(uint8_t id, uint16_t units) {
  Servo& s = servo(id);
  s.position = std::min(units, kMaxPosition);
  set_u16(s.table, kGoalPosition, static_cast<uint16_t>(s.position));
  refresh(s);
}

void SimulatedAx12Chain::set_fault(uint8_t id, Ax12Fault fault) {
  Servo& s = servo(id);
  const Ax12Fault previous = std::exchange(s.fault, fault);
  // A servo that cooled down (or was cooled in the test) is back at ambient at once.
  if (previous == Ax12Fault::kOverheat && fault != Ax12Fault::kOverheat) {
    s.temperature_c = options_.ambient_temperature_c;
  }
  refresh(s);
}

Ax12Fault SimulatedAx12Chain::fault(uint8_t id) const { return servo(id).fault; }

uint8_t SimulatedAx12Chain::condition(uint8_t id) const { return condition_of(servo(id)); }

}  // namespace mocap::dynamixel
