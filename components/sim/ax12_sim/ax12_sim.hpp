// A chain of simulated AX-12A servos on one Protocol 1.0 bus (protocol.hpp), for the turret
// follower to drive when no servos are attached, and for tests. It takes the bytes a host
// writes, answers them as the servos would, and moves the servos in time. The caller gives
// the time, so the simulation is deterministic and needs no serial device; the ax12_sim
// plugin plays it on a pseudo-terminal.
//
// Each servo has the full AX-12A control table (ax12_control_table.hpp) with the factory
// defaults and its own ID, and:
//   - answers PING, READ, WRITE, REG_WRITE / ACTION, RESET (ID back to 1) and, without a
//     status packet, SYNC_WRITE and anything sent to the broadcast ID; the status return
//     level register decides which instructions get an answer, as on the real servo (the
//     level before the instruction: the WRITE that changes it is answered as before);
//   - refuses with error bits: a bad checksum (kChecksum), an unknown instruction or ACTION
//     without REG_WRITE (kInstruction), a value outside a register's range, a write to a
//     read-only register or past the table, a write outside 24..35 while locked (kRange); a
//     goal position outside the angle limits is not executed (kAngleLimit), the rest of the
//     same WRITE is;
//   - reports its own condition in every status packet: supply outside the voltage limits
//     (kInputVoltage), present temperature above the temperature limit (kOverheating),
//     overload (kOverload); a condition listed in alarm shutdown keeps the torque off;
//   - with torque enabled, moves its present position toward the goal at the moving speed
//     (0: the no-load maximum, about 114 rpm at 12 V), or turns continuously in wheel mode
//     (both angle limits 0); reports present speed, a load proportional to the speed, and a
//     temperature that follows the load.
//
// The status packet carries the ID the instruction was sent to, also after a WRITE or RESET
// that changed the ID (as the manual's RESET example shows).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "follower/dynamixel/ax12_control_table.hpp"
#include "follower/dynamixel/protocol.hpp"

namespace mocap::dynamixel {

enum class Ax12Fault {
  kNone,
  // Ignores the bus: neither executes instructions nor answers, as a servo whose data line
  // is cut. It still moves toward the goal it had.
  kSilent,
  // Executes and answers, but every status packet has a wrong checksum (a noisy line).
  kCorruptReplies,
  // The present temperature is 5 degrees above the temperature limit: the overheating bit is
  // set in every answer, and the torque stays off while alarm shutdown lists overheating.
  kOverheat,
  // The servo is blocked: full load, the overload bit in every answer, and the torque off
  // while alarm shutdown lists overload.
  kOverload,
};

// "none", "silent", "corrupt", "overheat", "overload".
std::string_view to_string(Ax12Fault fault);
// The inverse of to_string; nullopt for any other name.
std::optional<Ax12Fault> parse_ax12_fault(std::string_view name);
// "ID:FAULT", e.g. "2:overheat", as the ax12_sim plugin's `faults` parameter lists them.
// Throws std::invalid_argument naming the text and the fault names.
std::pair<uint8_t, Ax12Fault> parse_ax12_fault_spec(std::string_view text);

struct SimulatedAx12ChainOptions {
  // Supply voltage; the servos' speed scales with it (the no-load maximum is quoted at 12 V).
  double supply_voltage_v = 12.0;
  // The temperature of an idle servo, degrees Celsius.
  double ambient_temperature_c = 30.0;
  // How much warmer than ambient a servo at full load settles, and how fast it gets there
  // (first order).
  double heating_at_full_load_c = 25.0;
  double thermal_time_constant_s = 60.0;
  // The present load while moving at the no-load maximum speed, as a fraction of the maximum
  // torque; the load is proportional to the speed, and 0 at rest.
  double load_at_full_speed = 0.3;
};

struct SimulatedAx12ChainStats {
  uint64_t instructions = 0;     // instruction packets read, bad checksums included
  uint64_t replies = 0;          // status packets sent
  uint64_t checksum_errors = 0;  // instruction packets with a bad checksum
  uint64_t unaddressed = 0;      // packets for an ID no servo in the chain has
  uint64_t ignored_bytes = 0;    // bytes outside packets
};

// Not thread-safe.
class SimulatedAx12Chain {
 public:
  // Servos with these IDs (0..253, distinct), factory defaults, at the centre (512), torque
  // off. Throws std::invalid_argument for an ID out of range or given twice.
  explicit SimulatedAx12Chain(std::span<const uint8_t> ids, SimulatedAx12ChainOptions options = {});

  // Takes bytes the host wrote (packets may be split across calls), at `time_s` (seconds on
  // any clock that never goes back; advance(time_s) is applied first), and returns the status
  // packets the servos send back, in order; "" when none is due.
  std::string feed(std::string_view bytes, double time_s);
  // Moves the servos to `time_s`. The first call (or feed) only sets the clock; a time before
  // the last one is ignored.
  void advance(double time_s);

  // --- Set-up and inspection, by the servo's present ID; std::out_of_range for an ID no
  // servo has.

  bool has_servo(uint8_t id) const;
  // The servos' present IDs, in chain order.
  std::vector<uint8_t> ids() const;
  uint8_t register_u8(uint8_t id, uint8_t address) const;
  uint16_t register_u16(uint8_t id, uint8_t address) const;
  // The exact position, in position units (the present position register rounds it).
  double position(uint8_t id) const;
  // Puts the servo at `units` (0..1023) with its goal there too, as after power-on.
  void set_position(uint8_t id, uint16_t units);
  void set_fault(uint8_t id, Ax12Fault fault);
  Ax12Fault fault(uint8_t id) const;
  // The error bits the servo reports about itself now: voltage, overheating, overload.
  uint8_t condition(uint8_t id) const;

  const SimulatedAx12ChainOptions& options() const { return options_; }
  const SimulatedAx12ChainStats& stats() const { return stats_; }

 private:
  struct Servo {
    std::array<uint8_t, ax12::kControlTableSize> table{};
    double position = ax12::kCentrePosition;  // units, unrounded
    double temperature_c = 0;
    double speed_rpm = 0;  // counter-clockwise positive; 0 at rest or with the torque off
    Ax12Fault fault = Ax12Fault::kNone;
    std::vector<uint8_t> registered;  // address and data of a REG_WRITE waiting for ACTION
  };

  std::string execute(const Packet& packet);
  // The status packet `servo` sends for an instruction to `id`, or "" when status return
  // level `level` says none is due.
  std::string answer(Servo& servo, uint8_t id, uint8_t instruction, uint8_t level, uint8_t errors,
                     std::span<const uint8_t> data);
  uint8_t execute_one(Servo& servo, const Packet& packet, std::vector<uint8_t>& data);
  uint8_t write_registers(Servo& servo, uint8_t address, std::span<const uint8_t> data, bool apply);
  void sync_write(std::span<const uint8_t> parameters);
  void reset(Servo& servo);
  void step(Servo& servo, double dt);
  void refresh(Servo& servo);
  uint8_t condition_of(const Servo& servo) const;
  std::vector<Servo*> servos_with(uint8_t id);
  Servo& servo(uint8_t id);
  const Servo& servo(uint8_t id) const;

  SimulatedAx12ChainOptions options_;
  std::vector<Servo> servos_;
  PacketParser parser_;
  std::optional<double> time_s_;
  SimulatedAx12ChainStats stats_;
};

}  // namespace mocap::dynamixel
