// The simulated AX-12A chain on its own, bytes in and bytes out, on the caller's clock: the
// answers to each instruction, motion toward the goal at the moving speed, the angle limits,
// the torque switch, error bits and each injected fault.
#include <gtest/gtest.h>

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "follower/dynamixel/ax12_control_table.hpp"
#include "follower/dynamixel/protocol.hpp"
#include "sim/ax12_sim/ax12_sim.hpp"

namespace mocap::dynamixel {
namespace {

using namespace ax12;

// 360 degrees a minute per rpm, over 300/1024 degrees per position unit.
constexpr double kUnitsPerSecondPerRpm = 6.0 * 1024.0 / 300.0;

// The one status packet `instruction` gets at `time_s`, or nullopt when none comes back.
std::optional<Packet> exchange(SimulatedAx12Chain& chain, const std::string& instruction,
                               double time_s) {
  const std::string reply = chain.feed(instruction, time_s);
  if (reply.empty()) return std::nullopt;
  PacketParser parser;
  parser.feed(reply);
  std::vector<Packet> packets = parser.take_packets();
  EXPECT_EQ(packets.size(), 1u);
  EXPECT_EQ(parser.pending_bytes(), 0u);
  EXPECT_EQ(parser.stats().checksum_errors, 0u);
  if (packets.empty()) return std::nullopt;
  return packets.front();
}

// The error byte of the answer to a WRITE; fails the test when there is none.
uint8_t write_u16(SimulatedAx12Chain& chain, uint8_t id, uint8_t address, uint16_t value,
                  double time_s) {
  const auto data = u16_bytes(value);
  const std::optional<Packet> reply = exchange(chain, encode_write(id, address, data), time_s);
  EXPECT_TRUE(reply.has_value()) << "no answer to a WRITE of " << int{address};
  return reply ? reply->code : 0xFF;
}

uint8_t write_u8(SimulatedAx12Chain& chain, uint8_t id, uint8_t address, uint8_t value,
                 double time_s) {
  const std::array<uint8_t, 1> data{value};
  const std::optional<Packet> reply = exchange(chain, encode_write(id, address, data), time_s);
  EXPECT_TRUE(reply.has_value()) << "no answer to a WRITE of " << int{address};
  return reply ? reply->code : 0xFF;
}

// Advances from `from_s` to `to_s` in 2 ms steps, as the plugin does.
void run(SimulatedAx12Chain& chain, double from_s, double to_s) {
  for (double t = from_s; t < to_s; t += 0.002) chain.advance(t);
  chain.advance(to_s);
}

std::vector<uint8_t> ids(std::initializer_list<uint8_t> list) { return list; }

TEST(SimulatedAx12Chain, AnswersPingAndReadWithTheFactoryDefaults) {
  const std::vector<uint8_t> chain_ids = ids({1, 2});
  SimulatedAx12Chain chain(chain_ids);
  EXPECT_EQ(chain.feed(encode_ping(1), 0), encode_status(1, 0));
  EXPECT_EQ(chain.feed(encode_ping(2), 0), encode_status(2, 0));
  EXPECT_EQ(chain.feed(encode_ping(3), 0), "");  // nobody has ID 3
  EXPECT_EQ(chain.feed(encode_ping(kBroadcastId), 0), "");
  EXPECT_EQ(chain.stats().unaddressed, 1u);

  // The whole control table of servo 2 in one READ.
  const std::optional<Packet> table = exchange(chain, encode_read(2, 0, kControlTableSize), 0);
  ASSERT_TRUE(table.has_value());
  EXPECT_EQ(table->id, 2);
  EXPECT_EQ(table->code, 0);
  ASSERT_EQ(table->parameters.size(), kControlTableSize);
  const std::vector<uint8_t>& t = table->parameters;
  EXPECT_EQ(get_u16(t, kModelNumber), 12);
  EXPECT_EQ(t[kId], 2);
  EXPECT_EQ(t[kBaudRate], 1);
  EXPECT_EQ(t[kReturnDelayTime], 250);
  EXPECT_EQ(get_u16(t, kCwAngleLimit), 0);
  EXPECT_EQ(get_u16(t, kCcwAngleLimit), 1023);
  EXPECT_EQ(t[kTemperatureLimit], 70);
  EXPECT_EQ(t[kMinVoltageLimit], 60);
  EXPECT_EQ(t[kMaxVoltageLimit], 140);
  EXPECT_EQ(get_u16(t, kMaxTorque), 1023);
  EXPECT_EQ(t[kStatusReturnLevel], 2);
  EXPECT_EQ(t[kAlarmShutdown], 36);
  EXPECT_EQ(t[kTorqueEnable], 0);
  EXPECT_EQ(get_u16(t, kGoalPosition), 512);
  EXPECT_EQ(get_u16(t, kPresentPosition), 512);
  EXPECT_EQ(get_u16(t, kTorqueLimit), 1023);
  EXPECT_EQ(t[kPresentVoltage], 120);
  EXPECT_EQ(t[kPresentTemperature], 30);
  EXPECT_EQ(t[kMoving], 0);
  EXPECT_EQ(get_u16(t, kPunch), 32);
}

TEST(SimulatedAx12Chain, RefusesBadIds) {
  EXPECT_THROW(SimulatedAx12Chain{ids({1, 1})}, std::invalid_argument);
  EXPECT_THROW(SimulatedAx12Chain{ids({254})}, std::invalid_argument);
  const std::vector<uint8_t> one = ids({1});
  SimulatedAx12Chain chain(one);
  EXPECT_THROW(chain.position(9), std::out_of_range);
}

TEST(SimulatedAx12Chain, MovesTowardTheGoalAtTheMovingSpeed) {
  const std::vector<uint8_t> one = ids({1});
  SimulatedAx12Chain chain(one);
  EXPECT_EQ(write_u16(chain, 1, kMovingSpeed, 100, 0), 0);
  EXPECT_EQ(write_u16(chain, 1, kGoalPosition, 712, 0), 0);
  EXPECT_EQ(write_u8(chain, 1, kTorqueEnable, 1, 0), 0);

  // 100 units = 11.1 rpm = 227.3 position units per second.
  run(chain, 0, 0.5);
  const double expected = 512 + 100 * 0.111 * kUnitsPerSecondPerRpm * 0.5;
  EXPECT_NEAR(chain.position(1), expected, 0.01);
  EXPECT_NEAR(chain.register_u16(1, kPresentPosition), expected, 1);
  EXPECT_EQ(chain.register_u8(1, kMoving), 1);
  EXPECT_EQ(chain.register_u16(1, kPresentSpeed), 100);  // counter-clockwise: no direction bit
  const uint16_t load = chain.register_u16(1, kPresentLoad);
  EXPECT_GT(load, 0);  // proportional to the speed, same direction
  EXPECT_LT(load, 1024);

  // Arrived, and stopped there.
  run(chain, 0.5, 2);
  EXPECT_EQ(chain.register_u16(1, kPresentPosition), 712);
  EXPECT_EQ(chain.register_u8(1, kMoving), 0);
  EXPECT_EQ(chain.register_u16(1, kPresentSpeed), 0);
  EXPECT_EQ(chain.register_u16(1, kPresentLoad), 0);

  // Moving speed 0: the no-load maximum, 114 rpm at 12 V; clockwise now.
  EXPECT_EQ(write_u16(chain, 1, kMovingSpeed, 0, 2), 0);
  EXPECT_EQ(write_u16(chain, 1, kGoalPosition, 112, 2), 0);
  run(chain, 2, 2.1);
  EXPECT_NEAR(chain.position(1), 712 - 114 * kUnitsPerSecondPerRpm * 0.1, 0.01);
  EXPECT_LT(present_speed_to_rad_s(chain.register_u16(1, kPresentSpeed)), -11);
  EXPECT_LT(present_load_to_fraction(chain.register_u16(1, kPresentLoad)), 0);
  run(chain, 2.1, 3);
  EXPECT_EQ(chain.register_u16(1, kPresentPosition), 112);

  // The READ a host would use sees the same.
  const std::optional<Packet> reply = exchange(chain, encode_read(1, kPresentPosition, 2), 3);
  ASSERT_TRUE(reply.has_value());
  EXPECT_EQ(get_u16(reply->parameters, 0), 112);
}

TEST(SimulatedAx12Chain, GoalsOutsideTheAngleLimitsAreNotExecuted) {
  const std::vector<uint8_t> one = ids({1});
  SimulatedAx12Chain chain(one);
  // Both limits in one WRITE of 4 bytes.
  const std::vector<uint8_t> limits{200, 0, 0x20, 0x03};  // 200, 800
  std::optional<Packet> reply = exchange(chain, encode_write(1, kCwAngleLimit, limits), 0);
  ASSERT_TRUE(reply.has_value());
  EXPECT_EQ(reply->code, 0);
  EXPECT_EQ(chain.register_u16(1, kCcwAngleLimit), 800);

  EXPECT_EQ(write_u8(chain, 1, kTorqueEnable, 1, 0), 0);
  EXPECT_EQ(write_u16(chain, 1, kGoalPosition, 900, 0), error_bit::kAngleLimit);
  EXPECT_EQ(write_u16(chain, 1, kGoalPosition, 100, 0), error_bit::kAngleLimit);
  EXPECT_EQ(chain.register_u16(1, kGoalPosition), 512);
  // Goal and speed in one WRITE: the speed is taken, the goal is not.
  const std::vector<uint8_t> goal_and_speed{0x84, 0x03, 50, 0};  // 900, 50
  reply = exchange(chain, encode_write(1, kGoalPosition, goal_and_speed), 0);
  ASSERT_TRUE(reply.has_value());
  EXPECT_EQ(reply->code, error_bit::kAngleLimit);
  EXPECT_EQ(chain.register_u16(1, kGoalPosition), 512);
  EXPECT_EQ(chain.register_u16(1, kMovingSpeed), 50);
  run(chain, 0, 1);
  EXPECT_EQ(chain.register_u16(1, kPresentPosition), 512);
  // Inside the limits: executed.
  EXPECT_EQ(write_u16(chain, 1, kGoalPosition, 800, 1), 0);
  run(chain, 1, 10);
  EXPECT_EQ(chain.register_u16(1, kPresentPosition), 800);
}

TEST(SimulatedAx12Chain, NoMotionWithTheTorqueOff) {
  const std::vector<uint8_t> one = ids({1});
  SimulatedAx12Chain chain(one);
  EXPECT_EQ(write_u16(chain, 1, kGoalPosition, 800, 0), 0);
  run(chain, 0, 1);
  EXPECT_EQ(chain.position(1), 512);
  EXPECT_EQ(chain.register_u8(1, kMoving), 0);
  EXPECT_EQ(write_u8(chain, 1, kTorqueEnable, 1, 1), 0);
  run(chain, 1, 1.1);
  const double moved = chain.position(1);
  EXPECT_GT(moved, 512);
  EXPECT_EQ(write_u8(chain, 1, kTorqueEnable, 0, 1.1), 0);
  run(chain, 1.1, 3);
  EXPECT_EQ(chain.position(1), moved);
  EXPECT_EQ(chain.register_u16(1, kPresentSpeed), 0);
  // A torque limit of 0 holds it too.
  EXPECT_EQ(write_u8(chain, 1, kTorqueEnable, 1, 3), 0);
  EXPECT_EQ(write_u16(chain, 1, kTorqueLimit, 0, 3), 0);
  run(chain, 3, 4);
  EXPECT_EQ(chain.position(1), moved);
}

TEST(SimulatedAx12Chain, WheelModeTurnsAtTheMovingSpeed) {
  const std::vector<uint8_t> one = ids({1});
  SimulatedAx12Chain chain(one);
  EXPECT_EQ(write_u16(chain, 1, kCcwAngleLimit, 0, 0), 0);                  // CW is 0 already
  EXPECT_EQ(write_u16(chain, 1, kMovingSpeed, kDirectionBit | 100, 0), 0);  // clockwise
  EXPECT_EQ(write_u8(chain, 1, kTorqueEnable, 1, 0), 0);
  run(chain, 0, 0.5);
  EXPECT_NEAR(chain.position(1), 512 - 100 * 0.111 * kUnitsPerSecondPerRpm * 0.5, 0.01);
  EXPECT_EQ(chain.register_u16(1, kPresentSpeed), kDirectionBit | 100);
  EXPECT_EQ(chain.register_u8(1, kMoving), 1);
  // In joint mode the direction bit is out of range.
  EXPECT_EQ(write_u16(chain, 1, kCcwAngleLimit, 1023, 0.5), error_bit::kRange);
}

TEST(SimulatedAx12Chain, RangeAndInstructionErrors) {
  const std::vector<uint8_t> one = ids({1});
  SimulatedAx12Chain chain(one);
  EXPECT_EQ(write_u8(chain, 1, kTorqueEnable, 2, 0), error_bit::kRange);
  EXPECT_EQ(chain.register_u8(1, kTorqueEnable), 0);
  EXPECT_EQ(write_u16(chain, 1, kGoalPosition, 1024, 0), error_bit::kRange);
  EXPECT_EQ(write_u16(chain, 1, kMovingSpeed, 1500, 0), error_bit::kRange);   // joint mode
  EXPECT_EQ(write_u16(chain, 1, kPresentPosition, 3, 0), error_bit::kRange);  // read-only
  EXPECT_EQ(write_u8(chain, 1, 45, 1, 0), error_bit::kRange);                 // a gap
  EXPECT_EQ(write_u16(chain, 1, 49, 1, 0), error_bit::kRange);                // past the end
  EXPECT_EQ(write_u8(chain, 1, kStatusReturnLevel, 3, 0), error_bit::kRange);

  std::optional<Packet> reply = exchange(chain, encode_read(1, 48, 5), 0);
  ASSERT_TRUE(reply.has_value());
  EXPECT_EQ(reply->code, error_bit::kRange);
  EXPECT_TRUE(reply->parameters.empty());

  reply = exchange(chain, encode_packet(1, 0x42, {}), 0);
  ASSERT_TRUE(reply.has_value());
  EXPECT_EQ(reply->code, error_bit::kInstruction);
  reply = exchange(chain, encode_action(1), 0);  // nothing registered
  ASSERT_TRUE(reply.has_value());
  EXPECT_EQ(reply->code, error_bit::kInstruction);

  // Locked: only 24..35 can be written, until power-off.
  EXPECT_EQ(write_u8(chain, 1, kLock, 1, 0), 0);
  EXPECT_EQ(write_u16(chain, 1, kPunch, 0x40, 0), error_bit::kRange);
  EXPECT_EQ(write_u8(chain, 1, kLock, 0, 0), error_bit::kRange);
  EXPECT_EQ(write_u16(chain, 1, kGoalPosition, 600, 0), 0);
}

TEST(SimulatedAx12Chain, BadChecksumFromTheHostIsAnsweredWithTheChecksumBit) {
  const std::vector<uint8_t> one = ids({1});
  SimulatedAx12Chain chain(one);
  const auto goal = u16_bytes(700);
  std::string packet = encode_write(1, kGoalPosition, goal);
  packet.back() = static_cast<char>(packet.back() + 1);
  const std::optional<Packet> reply = exchange(chain, packet, 0);
  ASSERT_TRUE(reply.has_value());
  EXPECT_EQ(reply->code, error_bit::kChecksum);
  EXPECT_EQ(chain.register_u16(1, kGoalPosition), 512);  // not executed
  EXPECT_EQ(chain.stats().checksum_errors, 1u);
  // The next packet is read normally.
  EXPECT_EQ(write_u16(chain, 1, kGoalPosition, 700, 0), 0);
  EXPECT_EQ(chain.register_u16(1, kGoalPosition), 700);
}

TEST(SimulatedAx12Chain, PacketsSplitAcrossFeeds) {
  const std::vector<uint8_t> one = ids({1});
  SimulatedAx12Chain chain(one);
  const std::string packet = encode_read(1, kPresentTemperature, 1);
  std::string replies;
  for (char c : packet) replies += chain.feed(std::string_view(&c, 1), 0);
  const std::vector<uint8_t> temperature{30};
  EXPECT_EQ(replies, encode_status(1, 0, temperature));
}

TEST(SimulatedAx12Chain, RegWriteWaitsForAction) {
  const std::vector<uint8_t> two = ids({1, 2});
  SimulatedAx12Chain chain(two);
  const auto goal = u16_bytes(600);
  for (uint8_t id : {1, 2}) {
    const std::optional<Packet> reply =
        exchange(chain, encode_reg_write(id, kGoalPosition, goal), 0);
    ASSERT_TRUE(reply.has_value());
    EXPECT_EQ(reply->code, 0);
    EXPECT_EQ(chain.register_u8(id, kRegistered), 1);
    EXPECT_EQ(chain.register_u16(id, kGoalPosition), 512);
  }
  EXPECT_EQ(chain.feed(encode_action(), 0), "");  // broadcast: no answer
  for (uint8_t id : {1, 2}) {
    EXPECT_EQ(chain.register_u16(id, kGoalPosition), 600);
    EXPECT_EQ(chain.register_u8(id, kRegistered), 0);
  }
}

TEST(SimulatedAx12Chain, SyncWriteReachesEveryListedServoWithoutAnswers) {
  const std::vector<uint8_t> three = ids({1, 2, 3});
  SimulatedAx12Chain chain(three);
  const std::vector<SyncWriteItem> torque{{1, {1}}, {2, {1}}};
  EXPECT_EQ(chain.feed(encode_sync_write(kTorqueEnable, 1, torque), 0), "");
  const std::vector<SyncWriteItem> goals{{1, {0x00, 0x03, 0, 0}}, {2, {0x00, 0x01, 0, 0}}};
  EXPECT_EQ(chain.feed(encode_sync_write(kGoalPosition, 4, goals), 0), "");
  run(chain, 0, 2);
  EXPECT_EQ(chain.register_u16(1, kPresentPosition), 768);
  EXPECT_EQ(chain.register_u16(2, kPresentPosition), 256);
  EXPECT_EQ(chain.register_u16(3, kPresentPosition), 512);  // not listed
  EXPECT_EQ(chain.stats().replies, 0u);
}

TEST(SimulatedAx12Chain, StatusReturnLevel) {
  const std::vector<uint8_t> one = ids({1});
  SimulatedAx12Chain chain(one);
  // Level 1: PING and READ answered. The WRITE that sets it still is, under level 2.
  EXPECT_EQ(write_u8(chain, 1, kStatusReturnLevel, 1, 0), 0);
  EXPECT_NE(chain.feed(encode_ping(1), 0), "");
  EXPECT_NE(chain.feed(encode_read(1, kId, 1), 0), "");
  const std::array<uint8_t, 1> led{1};
  EXPECT_EQ(chain.feed(encode_write(1, kLed, led), 0), "");
  EXPECT_EQ(chain.register_u8(1, kLed), 1);
  const std::array<uint8_t, 1> level_0{0};
  EXPECT_EQ(chain.feed(encode_write(1, kStatusReturnLevel, level_0), 0), "");
  EXPECT_EQ(chain.register_u8(1, kStatusReturnLevel), 0);
  EXPECT_EQ(chain.feed(encode_read(1, kId, 1), 0), "");
  EXPECT_EQ(chain.feed(encode_ping(1), 0), encode_status(1, 0));
}

TEST(SimulatedAx12Chain, IdChangeAndReset) {
  const std::vector<uint8_t> two = ids({1, 2});
  SimulatedAx12Chain chain(two);
  // The answer carries the ID the instruction was sent to.
  EXPECT_EQ(write_u8(chain, 1, kId, 5, 0), 0);
  EXPECT_EQ(chain.ids(), ids({5, 2}));
  EXPECT_EQ(chain.feed(encode_ping(1), 0), "");
  EXPECT_EQ(chain.feed(encode_ping(5), 0), encode_status(5, 0));
  EXPECT_EQ(write_u16(chain, 5, kCcwAngleLimit, 900, 0), 0);
  EXPECT_EQ(chain.feed(encode_reset(5), 0), encode_status(5, 0));
  EXPECT_EQ(chain.ids(), ids({1, 2}));
  EXPECT_EQ(chain.register_u16(1, kCcwAngleLimit), 1023);
}

TEST(SimulatedAx12Chain, InputVoltageOutsideTheLimits) {
  const std::vector<uint8_t> one = ids({1});
  SimulatedAx12Chain chain(one, SimulatedAx12ChainOptions{.supply_voltage_v = 5.0});
  EXPECT_EQ(chain.feed(encode_ping(1), 0), encode_status(1, error_bit::kInputVoltage));
  EXPECT_EQ(chain.register_u8(1, kPresentVoltage), 50);
}

TEST(SimulatedAx12Chain, TemperatureFollowsTheLoad) {
  const std::vector<uint8_t> one = ids({1});
  SimulatedAx12Chain chain(one);
  EXPECT_EQ(write_u16(chain, 1, kCcwAngleLimit, 0, 0), 0);  // wheel mode
  EXPECT_EQ(write_u16(chain, 1, kMovingSpeed, 1023, 0), 0);
  EXPECT_EQ(write_u8(chain, 1, kTorqueEnable, 1, 0), 0);
  for (double t = 0; t < 600; t += 0.05) chain.advance(t);
  // Settles at 30 + 25 * 0.3 * 113.6 / 114 = 37.5 degrees, ten time constants later.
  EXPECT_NEAR(chain.register_u8(1, kPresentTemperature), 37, 1);
  EXPECT_EQ(chain.condition(1), 0);
}

// --- Faults --------------------------------------------------------------------------------

TEST(SimulatedAx12Faults, SilentServoNeitherAnswersNorExecutes) {
  const std::vector<uint8_t> two = ids({1, 2});
  SimulatedAx12Chain chain(two);
  chain.set_fault(2, Ax12Fault::kSilent);
  EXPECT_EQ(chain.feed(encode_ping(2), 0), "");
  const auto goal = u16_bytes(700);
  EXPECT_EQ(chain.feed(encode_write(2, kGoalPosition, goal), 0), "");
  EXPECT_EQ(chain.register_u16(2, kGoalPosition), 512);
  EXPECT_EQ(chain.feed(encode_ping(1), 0), encode_status(1, 0));  // the other one does
  chain.set_fault(2, Ax12Fault::kNone);
  EXPECT_EQ(chain.feed(encode_ping(2), 0), encode_status(2, 0));
}

TEST(SimulatedAx12Faults, CorruptRepliesHaveBadChecksumsButInstructionsExecute) {
  const std::vector<uint8_t> one = ids({1});
  SimulatedAx12Chain chain(one);
  chain.set_fault(1, Ax12Fault::kCorruptReplies);
  const auto goal = u16_bytes(700);
  const std::string reply = chain.feed(encode_write(1, kGoalPosition, goal), 0);
  ASSERT_EQ(reply.size(), 6u);
  PacketParser parser;
  parser.feed(reply);
  EXPECT_TRUE(parser.take_packets().empty());
  EXPECT_EQ(parser.stats().checksum_errors, 1u);
  EXPECT_EQ(chain.register_u16(1, kGoalPosition), 700);
}

TEST(SimulatedAx12Faults, OverheatSetsTheBitAndShutsTheTorqueOff) {
  const std::vector<uint8_t> one = ids({1});
  SimulatedAx12Chain chain(one);
  EXPECT_EQ(write_u8(chain, 1, kTorqueEnable, 1, 0), 0);
  chain.set_fault(1, Ax12Fault::kOverheat);
  EXPECT_EQ(chain.register_u8(1, kTorqueEnable), 0);
  // Every answer has the bit; a READ still has its data: 5 degrees above the limit of 70.
  std::optional<Packet> reply = exchange(chain, encode_read(1, kPresentTemperature, 1), 0);
  ASSERT_TRUE(reply.has_value());
  EXPECT_EQ(reply->code, error_bit::kOverheating);
  EXPECT_EQ(reply->parameters, std::vector<uint8_t>{75});
  // The torque cannot come back while it lasts.
  EXPECT_EQ(write_u8(chain, 1, kTorqueEnable, 1, 0), error_bit::kOverheating);
  EXPECT_EQ(write_u16(chain, 1, kGoalPosition, 800, 0), error_bit::kOverheating);
  run(chain, 0, 1);
  EXPECT_EQ(chain.position(1), 512);
  // Unless alarm shutdown leaves overheating out.
  EXPECT_EQ(write_u8(chain, 1, kAlarmShutdown, error_bit::kOverload, 1), error_bit::kOverheating);
  EXPECT_EQ(write_u8(chain, 1, kTorqueEnable, 1, 1), error_bit::kOverheating);
  run(chain, 1, 2);
  EXPECT_GT(chain.position(1), 512);
  // Cooled down: the bit goes.
  chain.set_fault(1, Ax12Fault::kNone);
  EXPECT_EQ(chain.feed(encode_ping(1), 2), encode_status(1, 0));
  EXPECT_EQ(chain.register_u8(1, kPresentTemperature), 30);
}

TEST(SimulatedAx12Faults, OverloadSetsTheBitAndStopsTheServo) {
  const std::vector<uint8_t> one = ids({1});
  SimulatedAx12Chain chain(one);
  EXPECT_EQ(write_u8(chain, 1, kTorqueEnable, 1, 0), 0);
  EXPECT_EQ(write_u16(chain, 1, kMovingSpeed, 100, 0), 0);
  EXPECT_EQ(write_u16(chain, 1, kGoalPosition, 900, 0), 0);
  run(chain, 0, 0.5);
  const double blocked_at = chain.position(1);
  EXPECT_GT(blocked_at, 600);
  chain.set_fault(1, Ax12Fault::kOverload);
  const std::optional<Packet> reply = exchange(chain, encode_read(1, kTorqueEnable, 1), 0.5);
  ASSERT_TRUE(reply.has_value());
  EXPECT_EQ(reply->code, error_bit::kOverload);
  EXPECT_EQ(reply->parameters, std::vector<uint8_t>{0});  // torque off by alarm shutdown
  EXPECT_EQ(chain.register_u16(1, kPresentLoad), 1023);   // full load, toward the goal
  run(chain, 0.5, 2);
  EXPECT_EQ(chain.position(1), blocked_at);
  chain.set_fault(1, Ax12Fault::kNone);
  EXPECT_EQ(chain.condition(1), 0);
  EXPECT_EQ(chain.register_u16(1, kPresentLoad), 0);
}

TEST(SimulatedAx12Faults, FaultSpecifications) {
  EXPECT_EQ(parse_ax12_fault_spec("2:overheat"), std::make_pair(uint8_t{2}, Ax12Fault::kOverheat));
  EXPECT_EQ(parse_ax12_fault_spec("253:silent"), std::make_pair(uint8_t{253}, Ax12Fault::kSilent));
  EXPECT_EQ(parse_ax12_fault_spec("0:corrupt").second, Ax12Fault::kCorruptReplies);
  EXPECT_EQ(parse_ax12_fault_spec("1:overload").second, Ax12Fault::kOverload);
  EXPECT_EQ(parse_ax12_fault_spec("1:none").second, Ax12Fault::kNone);
  for (const char* bad : {"2", "2:", ":silent", "x:silent", "254:silent", "2:melt", "1234:none"}) {
    EXPECT_THROW(parse_ax12_fault_spec(bad), std::invalid_argument) << bad;
  }
  for (Ax12Fault fault : {Ax12Fault::kNone, Ax12Fault::kSilent, Ax12Fault::kCorruptReplies,
                          Ax12Fault::kOverheat, Ax12Fault::kOverload}) {
    EXPECT_EQ(parse_ax12_fault(to_string(fault)), fault);
  }
}

}  // namespace
}  // namespace mocap::dynamixel
