// The AX-12A's control table (ROBOTIS e-manual, AX-12A): the registers a host reads and
// writes through READ and WRITE, where they are, how wide, their factory defaults and the
// values the servo accepts; and the conversions between register units and SI units.
//
// Addresses 0..23 are EEPROM (kept across power cycles), 24..49 RAM. Two-byte registers are
// little-endian, low byte at the lower address. Positions count 0..1023 over 300 degrees,
// clockwise to counter-clockwise, 512 at the centre; the 60 degrees behind the servo cannot
// be reached.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace mocap::dynamixel::ax12 {

// --- Addresses -----------------------------------------------------------------------------

// EEPROM
constexpr uint8_t kModelNumber = 0;         // 2 bytes, read-only: 12
constexpr uint8_t kFirmwareVersion = 2;     // read-only
constexpr uint8_t kId = 3;                  // 0..253
constexpr uint8_t kBaudRate = 4;            // 2000000 / (value + 1) bit/s; 1 = 1 Mbit/s
constexpr uint8_t kReturnDelayTime = 5;     // 2 us units before a status packet
constexpr uint8_t kCwAngleLimit = 6;        // 2 bytes; CW = CCW = 0 selects wheel mode
constexpr uint8_t kCcwAngleLimit = 8;       // 2 bytes
constexpr uint8_t kTemperatureLimit = 11;   // degrees Celsius
constexpr uint8_t kMinVoltageLimit = 12;    // 0.1 V
constexpr uint8_t kMaxVoltageLimit = 13;    // 0.1 V
constexpr uint8_t kMaxTorque = 14;          // 2 bytes; copied to kTorqueLimit at power-on
constexpr uint8_t kStatusReturnLevel = 16;  // 0: PING only, 1: PING and READ, 2: all
constexpr uint8_t kAlarmLed = 17;           // error bits that blink the LED
constexpr uint8_t kAlarmShutdown = 18;      // error bits that switch the torque off
// RAM
constexpr uint8_t kTorqueEnable = 24;
constexpr uint8_t kLed = 25;
constexpr uint8_t kCwComplianceMargin = 26;
constexpr uint8_t kCcwComplianceMargin = 27;
constexpr uint8_t kCwComplianceSlope = 28;
constexpr uint8_t kCcwComplianceSlope = 29;
constexpr uint8_t kGoalPosition = 30;        // 2 bytes
constexpr uint8_t kMovingSpeed = 32;         // 2 bytes; joint mode 0..1023, wheel mode 0..2047
constexpr uint8_t kTorqueLimit = 34;         // 2 bytes
constexpr uint8_t kPresentPosition = 36;     // 2 bytes, read-only
constexpr uint8_t kPresentSpeed = 38;        // 2 bytes, read-only, direction bit 10
constexpr uint8_t kPresentLoad = 40;         // 2 bytes, read-only, direction bit 10
constexpr uint8_t kPresentVoltage = 42;      // read-only, 0.1 V
constexpr uint8_t kPresentTemperature = 43;  // read-only, degrees Celsius
constexpr uint8_t kRegistered = 44;          // read-only: a REG_WRITE waits for ACTION
constexpr uint8_t kMoving = 46;              // read-only: still travelling to the goal
constexpr uint8_t kLock = 47;                // 1: only 24..35 writable until power-off
constexpr uint8_t kPunch = 48;               // 2 bytes

// Addresses 0..kControlTableSize - 1 exist; gaps between registers read as 0 and refuse
// writes.
constexpr size_t kControlTableSize = 50;
// The first RAM address; below it, EEPROM.
constexpr uint8_t kFirstRamAddress = 24;
// The model number an AX-12A answers with.
constexpr uint16_t kModelNumberAx12 = 12;

// --- Register descriptions -----------------------------------------------------------------

struct Register {
  uint8_t address = 0;
  uint8_t width = 1;  // bytes: 1 or 2
  std::string_view name;
  bool read_only = false;
  // The factory default. Registers that the servo measures (present position, speed, load,
  // voltage, temperature) and the goal position, which it copies from the present position
  // at power-on, have 0 here.
  uint16_t default_value = 0;
  // The values a WRITE may set; anything else is a range error.
  uint16_t min_value = 0;
  uint16_t max_value = 0;

  bool eeprom() const { return address < kFirstRamAddress; }
};

// Every register, by address.
std::span<const Register> registers();
// The register starting at `address`, or nullptr (a gap, the second byte of a two-byte
// register, or past the end).
const Register* find_register(uint8_t address);
// The register that holds the byte at `address`, or nullptr for a gap or past the end.
const Register* register_at(uint8_t address);

// The factory control table of a servo with `id`: every register at its default, except ID.
std::array<uint8_t, kControlTableSize> default_control_table(uint8_t id = 1);

// --- Little-endian access ------------------------------------------------------------------

// The two bytes at bytes[offset], bytes[offset + 1], low first. The caller checks the size.
inline uint16_t get_u16(std::span<const uint8_t> bytes, size_t offset) {
  return static_cast<uint16_t>(bytes[offset] | (bytes[offset + 1] << 8));
}
// `value` as WRITE sends it: low byte, high byte.
inline std::array<uint8_t, 2> u16_bytes(uint16_t value) {
  return {static_cast<uint8_t>(value & 0xFF), static_cast<uint8_t>(value >> 8)};
}

// --- Unit conversions ----------------------------------------------------------------------

constexpr uint16_t kMaxPosition = 1023;
constexpr uint16_t kCentrePosition = 512;
// 1024 steps over 300 degrees, so that 512 is the centre exactly; 1023 is the last step.
constexpr double kRadiansPerPositionUnit = 300.0 / 1024.0 * 3.14159265358979323846 / 180.0;
// Moving and present speed: 0.111 rpm per unit.
constexpr double kRpmPerSpeedUnit = 0.111;
constexpr double kRadPerSecondPerSpeedUnit = kRpmPerSpeedUnit * 2 * 3.14159265358979323846 / 60;
// The no-load speed at 12 V (about 114 rpm), which moving speed 0 asks for in joint mode.
constexpr double kMaxSpeedRpmAt12V = 114.0;
// Bit 10 of present speed, present load and (wheel mode) moving speed: set = clockwise.
constexpr uint16_t kDirectionBit = 1 << 10;

// Radians from the centre, counter-clockwise positive, for a position register value (values
// above 1023 count as 1023).
double position_to_radians(uint16_t units);
// The nearest position register value for an angle from the centre, clamped to 0..1023.
uint16_t radians_to_position(double radians);

// The joint-mode speed that moving speed `units` asks for, rad/s: units * 0.111 rpm, and the
// no-load maximum for 0 (the servo then moves as fast as it can, without speed control).
// Values above 1023 count as 1023.
double moving_speed_to_rad_s(uint16_t units);
// The moving speed register value for `rad_s` (its magnitude), 1..1023: never 0, which would
// mean "as fast as possible" rather than "slowly".
uint16_t rad_s_to_moving_speed(double rad_s);

// A present speed or present load value as a signed magnitude: bits 0..9, negative when the
// direction bit is set (clockwise), e.g. 1024 + 100 -> -100.
int from_direction_bit(uint16_t raw);
// The inverse: |value| clamped to 1023 in bits 0..9, the direction bit for negative values.
uint16_t to_direction_bit(int value);

// Present speed in rad/s, counter-clockwise positive.
double present_speed_to_rad_s(uint16_t raw);
// Present load as a fraction of the maximum torque, -1..1, counter-clockwise positive.
double present_load_to_fraction(uint16_t raw);
// Present voltage and the voltage limits: 0.1 V per unit.
double voltage_to_volts(uint8_t raw);
// Present temperature and the temperature limit are plain degrees Celsius.
inline double temperature_to_celsius(uint8_t raw) { return raw; }

}  // namespace mocap::dynamixel::ax12
