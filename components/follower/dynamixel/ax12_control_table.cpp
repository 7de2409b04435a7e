#include "follower/dynamixel/ax12_control_table.hpp"

#include <algorithm>
#include <cmath>

namespace mocap::dynamixel::ax12 {
namespace {

// Firmware 24 is what AX-12As in the field commonly report; hosts do not depend on it.
constexpr uint16_t kFirmware = 24;

// clang-format off
constexpr std::array<Register, 32> kRegisters{{
    // address, width, name, read-only, default, min, max
    {kModelNumber,         2, "model number",          true,  kModelNumberAx12, 0, 0},
    {kFirmwareVersion,     1, "firmware version",      true,  kFirmware, 0, 0},
    {kId,                  1, "ID",                    false, 1,    0, 253},
    {kBaudRate,            1, "baud rate",             false, 1,    0, 254},
    {kReturnDelayTime,     1, "return delay time",     false, 250,  0, 254},
    {kCwAngleLimit,        2, "CW angle limit",        false, 0,    0, 1023},
    {kCcwAngleLimit,       2, "CCW angle limit",       false, 1023, 0, 1023},
    {kTemperatureLimit,    1, "temperature limit",     false, 70,   0, 99},
    {kMinVoltageLimit,     1, "min voltage limit",     false, 60,   50, 250},
    {kMaxVoltageLimit,     1, "max voltage limit",     false, 140,  50, 250},
    {kMaxTorque,           2, "max torque",            false, 1023, 0, 1023},
    {kStatusReturnLevel,   1, "status return level",   false, 2,    0, 2},
    {kAlarmLed,            1, "alarm LED",             false, 36,   0, 127},
    {kAlarmShutdown,       1, "alarm shutdown",        false, 36,   0, 127},
    {kTorqueEnable,        1, "torque enable",         false, 0,    0, 1},
    {kLed,                 1, "LED",                   false, 0,    0, 1},
    {kCwComplianceMargin,  1, "CW compliance margin",  false, 1,    0, 255},
    {kCcwComplianceMargin, 1, "CCW compliance margin", false, 1,    0, 255},
    {kCwComplianceSlope,   1, "CW compliance slope",   false, 32,   1, 254},
    {kCcwComplianceSlope,  1, "CCW compliance slope",  false, 32,   1, 254},
    {kGoalPosition,        2, "goal position",         false, 0,    0, 1023},
    {kMovingSpeed,         2, "moving speed",          false, 0,    0, 2047},
    {kTorqueLimit,         2, "torque limit",          false, 1023, 0, 1023},
    {kPresentPosition,     2, "present position",      true,  0,    0, 0},
    {kPresentSpeed,        2, "present speed",         true,  0,    0, 0},
    {kPresentLoad,         2, "present load",          true,  0,    0, 0},
    {kPresentVoltage,      1, "present voltage",       true,  0,    0, 0},
    {kPresentTemperature,  1, "present temperature",   true,  0,    0, 0},
    {kRegistered,          1, "registered",            true,  0,    0, 0},
    {kMoving,              1, "moving",                true,  0,    0, 0},
    {kLock,                1, "lock",                  false, 0,    0, 1},
    {kPunch,               2, "punch",                 false, 32,   0, 1023},
}};
// clang-format on

}  // namespace

std::span<const Register> registers() { return kRegisters; }

const Register* find_register(uint8_t address) {
  for (const Register& r : registers()) {
    if (r.address == address) return &r;
  }
  return nullptr;
}

const Register* register_at(uint8_t address) {
  for (const Register& r : registers()) {
    if (address >= r.address && address < r.address + r.width) return &r;
  }
  return nullptr;
}

std::array<uint8_t, kControlTableSize> default_control_table(uint8_t id) {
  std::array<uint8_t, kControlTableSize> table{};
  for (const Register& r : registers()) {
    table[r.address] = static_cast<uint8_t>(r.default_value & 0xFF);
    if (r.width == 2) table[r.address + 1u] = static_cast<uint8_t>(r.default_value >> 8);
  }
  table[kId] = id;
  return table;
}

double position_to_radians(uint16_t units) {
  const int clamped = std::min<int>(units, kMaxPosition);
  return (clamped - kCentrePosition) * kRadiansPerPositionUnit;
}

uint16_t radians_to_position(double radians) {
  const double units = std::round(kCentrePosition + radians / kRadiansPerPositionUnit);
  if (!(units > 0)) return 0;  // NaN as well
  return static_cast<uint16_t>(std::min(units, double{kMaxPosition}));
}

double moving_speed_to_rad_s(uint16_t units) {
  const int clamped = std::min<int>(units, 1023);
  if (clamped == 0) return kMaxSpeedRpmAt12V * 2 * 3.14159265358979323846 / 60;
  return clamped * kRadPerSecondPerSpeedUnit;
}

uint16_t rad_s_to_moving_speed(double rad_s) {
  const double units = std::round(std::abs(rad_s) / kRadPerSecondPerSpeedUnit);
  if (!(units >= 1)) return 1;  // NaN as well
  return static_cast<uint16_t>(std::min(units, 1023.0));
}

int from_direction_bit(uint16_t raw) {
  const int magnitude = raw & 0x3FF;
  return (raw & kDirectionBit) ? -magnitude : magnitude;
}

uint16_t to_direction_bit(int value) {
  const auto magnitude = static_cast<uint16_t>(std::min(std::abs(value), 1023));
  return value < 0 ? static_cast<uint16_t>(magnitude | kDirectionBit) : magnitude;
}

double present_speed_to_rad_s(uint16_t raw) {
  return from_direction_bit(raw) * kRadPerSecondPerSpeedUnit;
}

double present_load_to_fraction(uint16_t raw) { return from_direction_bit(raw) / 1023.0; }

double voltage_to_volts(uint8_t raw) { return raw * 0.1; }

}  // namespace mocap::dynamixel::ax12
