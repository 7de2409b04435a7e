// The Dynamixel driver against the simulated AX-12A chain over a real pseudo-terminal: the
// ax12_sim plugin runs in a ComponentHost without DDS, the driver opens its device link like
// a USB2Dynamixel. Round trips, SYNC_WRITE motion, every injected fault's error kind, and an
// unplugged adaptor.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <mocap/component_host.hpp>

#include "follower/dynamixel/ax12_control_table.hpp"
#include "follower/dynamixel/dynamixel_bus.hpp"
#include "follower/dynamixel/protocol.hpp"
#include "host/plugin_loader.hpp"
#include "test/test_support.hpp"

namespace mocap::dynamixel {
namespace {

using namespace ax12;

const ComponentFactory& ax12_factory() {
  static PluginLoader loader;
  return *loader.load("ax12_sim").factory;
}

HostOptions in_process() { return {.name = "test", .threads = 2, .dds = {.enabled = false}}; }

// The plugin in its own host, reachable at device(); unplug() ends it, closing the pty.
class SimulatedServos {
 public:
  explicit SimulatedServos(std::map<std::string, ParameterValue> parameters) {
    parameters["device_link"] = device();
    host_ = std::make_unique<ComponentHost>(in_process());
    host_->add(ax12_factory(), {.name = "servos", .parameters = std::move(parameters)});
    host_->start();
  }

  std::string device() const { return (dir_ / "ttyDXL").string(); }
  void unplug() { host_.reset(); }

 private:
  test::TempDir dir_;
  std::unique_ptr<ComponentHost> host_;
};

// The simulator's thread answers within microseconds, but a loaded machine may hold it up
// for a while; a generous timeout keeps the counts below exact. Failures take 3 timeouts.
DynamixelBusOptions test_options() {
  return DynamixelBusOptions{.reply_timeout = std::chrono::milliseconds(100), .retries = 2};
}

// Runs `call`, which must throw a BusError, and returns it.
template <class Call>
BusError bus_error_of(Call&& call) {
  try {
    call();
  } catch (const BusError& e) {
    return e;
  }
  ADD_FAILURE() << "no BusError";
  return BusError(BusErrorKind::kTimeout, 0, 0, "none");
}

TEST(DynamixelBus, PingReadAndWriteRoundTrips) {
  SimulatedServos servos(
      {{"ids", std::vector<int64_t>{1, 2}}, {"initial_positions", std::vector<int64_t>{300, 700}}});
  DynamixelBus bus(servos.device(), test_options());
  EXPECT_EQ(bus.ping(1), 0);
  EXPECT_EQ(bus.ping(2), 0);
  EXPECT_EQ(bus.read_u16(1, kModelNumber), kModelNumberAx12);
  EXPECT_EQ(bus.read_u16(1, kPresentPosition), 300);
  EXPECT_EQ(bus.read_u16(2, kPresentPosition), 700);
  EXPECT_EQ(bus.read_u8(2, kPresentTemperature), 30);

  bus.write_u16(1, kCcwAngleLimit, 1000);
  EXPECT_EQ(bus.read_u16(1, kCcwAngleLimit), 1000);
  bus.write_u8(2, kLed, 1);
  EXPECT_EQ(bus.read_u8(2, kLed), 1);
  EXPECT_EQ(bus.read_u8(1, kLed), 0);
  const std::vector<uint8_t> limits{10, 0, 0xE8, 0x03};  // CW 10, CCW 1000
  bus.write(2, kCwAngleLimit, limits);
  const std::vector<uint8_t> table = bus.read(2, 0, kControlTableSize);
  ASSERT_EQ(table.size(), kControlTableSize);
  EXPECT_EQ(table[kId], 2);
  EXPECT_EQ(get_u16(table, kCwAngleLimit), 10);
  EXPECT_EQ(get_u16(table, kCcwAngleLimit), 1000);
  EXPECT_EQ(table[kLed], 1);

  const DynamixelBusStats& stats = bus.stats();
  EXPECT_EQ(stats.packets_sent, 13u);
  EXPECT_EQ(stats.replies, 13u);
  EXPECT_EQ(stats.timeouts, 0u);
  EXPECT_EQ(stats.retries, 0u);
  EXPECT_EQ(stats.checksum_errors, 0u);
  EXPECT_EQ(stats.servo_errors, 0u);
}

TEST(DynamixelBus, AbsentServoTimesOut) {
  SimulatedServos servos({{"ids", std::vector<int64_t>{1}}});
  DynamixelBus bus(servos.device(), test_options());
  const BusError error = bus_error_of([&] { bus.ping(7); });
  EXPECT_EQ(error.kind(), BusErrorKind::kTimeout);
  EXPECT_EQ(error.id(), 7);
  EXPECT_EQ(error.instruction(), static_cast<uint8_t>(Instruction::kPing));
  EXPECT_NE(std::string(error.what()).find("servo 7, PING: no reply"), std::string::npos)
      << error.what();
  EXPECT_EQ(bus.stats().timeouts, 3u);
  EXPECT_EQ(bus.stats().retries, 2u);
  EXPECT_EQ(bus.ping(1), 0);  // the bus is fine
  EXPECT_THROW(bus.ping(kBroadcastId), std::invalid_argument);
}

TEST(DynamixelBus, StatusReturnLevelOne) {
  SimulatedServos servos({{"ids", std::vector<int64_t>{1}}});
  {
    DynamixelBus bus(servos.device(), test_options());
    bus.write_u8(1, kStatusReturnLevel, 1);
  }
  DynamixelBusOptions options = test_options();
  options.status_return_level = 1;
  DynamixelBus bus(servos.device(), options);
  bus.write_u16(1, kGoalPosition, 600);  // not answered, not waited for
  EXPECT_EQ(bus.stats().replies, 0u);
  EXPECT_EQ(bus.read_u16(1, kGoalPosition), 600);
  EXPECT_EQ(bus.ping(1), 0);
  EXPECT_EQ(bus.stats().replies, 2u);
  EXPECT_EQ(bus.stats().timeouts, 0u);
  // A servo that answers nothing but PING cannot be read.
  options.status_return_level = 0;
  bus.write_u8(1, kStatusReturnLevel, 0);
  DynamixelBus silent_reads(servos.device(), options);
  EXPECT_THROW(silent_reads.read_u8(1, kId), std::invalid_argument);
}

TEST(DynamixelBus, SyncWriteMovesBothServos) {
  SimulatedServos servos({{"ids", std::vector<int64_t>{1, 2}}});
  DynamixelBus bus(servos.device(), test_options());
  const std::vector<SyncWriteItem> torque{{1, {1}}, {2, {1}}};
  bus.sync_write(kTorqueEnable, 1, torque);
  // Goal and moving speed, 4 bytes from 30: servo 1 to 800, servo 2 to 200, both at 300
  // units (33 rpm).
  std::vector<SyncWriteItem> goals;
  const std::array<std::pair<uint8_t, uint16_t>, 2> targets{{{1, 800}, {2, 200}}};
  for (const auto& [id, goal] : targets) {
    const auto position = u16_bytes(goal), speed = u16_bytes(300);
    goals.push_back({id, {position[0], position[1], speed[0], speed[1]}});
  }
  bus.sync_write(kGoalPosition, 4, goals);
  EXPECT_EQ(bus.stats().replies, 0u);  // nobody answers a SYNC_WRITE

  EXPECT_EQ(bus.read_u8(1, kTorqueEnable), 1);
  EXPECT_EQ(bus.read_u16(1, kGoalPosition), 800);
  EXPECT_EQ(bus.read_u16(2, kGoalPosition), 200);
  EXPECT_EQ(bus.read_u16(2, kMovingSpeed), 300);
  // Until both report they stopped; the simulation's own clock decides how long that takes.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  bool moving = true;
  while (moving && std::chrono::steady_clock::now() < deadline) {
    moving = bus.read_u8(1, kMoving) != 0 || bus.read_u8(2, kMoving) != 0;
    if (moving) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_FALSE(moving);
  EXPECT_EQ(bus.read_u16(1, kPresentPosition), 800);
  EXPECT_EQ(bus.read_u16(2, kPresentPosition), 200);
  EXPECT_EQ(bus.read_u16(1, kPresentSpeed), 0);
}

TEST(DynamixelBus, ServoErrorsCarryTheBitsAndAreNotRetried) {
  SimulatedServos servos({{"ids", std::vector<int64_t>{1, 2, 3}},
                          {"faults", std::vector<std::string>{"1:overheat", "2:overload"}}});
  DynamixelBus bus(servos.device(), test_options());
  // A servo that reports a condition still answers a PING.
  EXPECT_EQ(bus.ping(1), error_bit::kOverheating);
  EXPECT_EQ(bus.ping(2), error_bit::kOverload);

  BusError error = bus_error_of([&] { bus.read_u8(1, kPresentTemperature); });
  EXPECT_EQ(error.kind(), BusErrorKind::kServoError);
  EXPECT_EQ(error.servo_errors(), error_bit::kOverheating);
  EXPECT_EQ(error.reply_data(), std::vector<uint8_t>{75});  // the data came anyway
  EXPECT_NE(std::string(error.what()).find("servo 1, READ: servo reports overheating"),
            std::string::npos)
      << error.what();

  error = bus_error_of([&] { bus.write_u8(2, kTorqueEnable, 1); });
  EXPECT_EQ(error.kind(), BusErrorKind::kServoError);
  EXPECT_EQ(error.id(), 2);
  EXPECT_EQ(error.servo_errors(), error_bit::kOverload);
  EXPECT_EQ(std::string(error.what()), "servo 2, WRITE: servo reports overload (error 0x20)");

  // Refused instructions: a value out of range, a goal outside the angle limits.
  error = bus_error_of([&] { bus.write_u8(3, kTorqueEnable, 5); });
  EXPECT_EQ(error.kind(), BusErrorKind::kServoError);
  EXPECT_EQ(error.servo_errors(), error_bit::kRange);
  bus.write_u16(3, kCwAngleLimit, 100);
  error = bus_error_of([&] { bus.write_u16(3, kGoalPosition, 50); });
  EXPECT_EQ(error.servo_errors(), error_bit::kAngleLimit);
  EXPECT_EQ(bus.read_u16(3, kGoalPosition), 512);

  EXPECT_EQ(bus.stats().retries, 0u);
  EXPECT_EQ(bus.stats().servo_errors, 6u);  // both pings included
}

TEST(DynamixelBus, SilentServoTimesOutAfterRetries) {
  SimulatedServos servos(
      {{"ids", std::vector<int64_t>{1, 2}}, {"faults", std::vector<std::string>{"2:silent"}}});
  DynamixelBus bus(servos.device(), test_options());
  const BusError error = bus_error_of([&] { bus.read_u16(2, kPresentPosition); });
  EXPECT_EQ(error.kind(), BusErrorKind::kTimeout);
  EXPECT_EQ(error.id(), 2);
  EXPECT_NE(std::string(error.what()).find("servo 2, READ: no reply within"), std::string::npos)
      << error.what();
  EXPECT_NE(std::string(error.what()).find("(3 attempts)"), std::string::npos) << error.what();
  EXPECT_EQ(bus.stats().packets_sent, 3u);
  EXPECT_EQ(bus.stats().timeouts, 3u);
  EXPECT_EQ(bus.stats().retries, 2u);
  EXPECT_EQ(bus.stats().replies, 0u);
  EXPECT_EQ(bus.read_u16(1, kPresentPosition), 512);
}

TEST(DynamixelBus, CorruptRepliesAreRetriedThenReported) {
  SimulatedServos servos(
      {{"ids", std::vector<int64_t>{1, 2}}, {"faults", std::vector<std::string>{"1:corrupt"}}});
  DynamixelBus bus(servos.device(), test_options());
  const BusError error = bus_error_of([&] { bus.read_u16(1, kPresentPosition); });
  EXPECT_EQ(error.kind(), BusErrorKind::kCorrupt);
  EXPECT_NE(std::string(error.what()).find("servo 1, READ: corrupt reply: bad checksum"),
            std::string::npos)
      << error.what();
  EXPECT_EQ(bus.stats().packets_sent, 3u);
  EXPECT_EQ(bus.stats().checksum_errors, 3u);
  EXPECT_EQ(bus.stats().corrupt_replies, 3u);
  EXPECT_EQ(bus.stats().retries, 2u);
  EXPECT_EQ(bus.stats().timeouts, 0u);
  // The next servo's answer is not confused with the garbled ones.
  EXPECT_EQ(bus.read_u8(2, kId), 2);
}

TEST(DynamixelBus, UnpluggedAdaptorIsPortGone) {
  SimulatedServos servos({{"ids", std::vector<int64_t>{1}}});
  DynamixelBus bus(servos.device(), test_options());
  EXPECT_EQ(bus.ping(1), 0);
  servos.unplug();
  BusError error = bus_error_of([&] { bus.read_u16(1, kPresentPosition); });
  EXPECT_EQ(error.kind(), BusErrorKind::kPortGone);
  EXPECT_TRUE(bus.port_gone());
  // Every later call fails the same way, at once.
  error = bus_error_of([&] { bus.ping(1); });
  EXPECT_EQ(error.kind(), BusErrorKind::kPortGone);
  EXPECT_NE(std::string(error.what()).find("servo 1, PING"), std::string::npos) << error.what();
  const std::vector<SyncWriteItem> items{{1, {1}}};
  error = bus_error_of([&] { bus.sync_write(kTorqueEnable, 1, items); });
  EXPECT_EQ(error.kind(), BusErrorKind::kPortGone);
  // The device itself is gone with the link.
  EXPECT_THROW(DynamixelBus{servos.device()}, serial::SerialError);
}

TEST(DynamixelBus, RefusesBadOptions) {
  EXPECT_EQ(DynamixelBusOptions{}.problem(), std::nullopt);
  EXPECT_EQ(DynamixelBusOptions{.retries = -1}.problem(), "retries: -1 is below 0");
  EXPECT_EQ(DynamixelBusOptions{.status_return_level = 3}.problem(),
            "status_return_level: 3 is not 0, 1 or 2");
  EXPECT_EQ(DynamixelBusOptions{.reply_timeout = std::chrono::milliseconds(-1)}.problem(),
            "reply_timeout: -1 ms is below 0");
  // The serial port's fields, named as the bus names them.
  EXPECT_EQ(DynamixelBusOptions{.write_timeout = std::chrono::milliseconds(-2)}.problem(),
            "write_timeout: -2 ms is below 0");
  EXPECT_EQ(DynamixelBusOptions{.baud_rate = 12345}.problem()->rfind(
                "baud_rate: 12345 is not supported; supported: 9600, ", 0),
            0u);
  SimulatedServos servos({{"ids", std::vector<int64_t>{1}}});
  try {
    DynamixelBus bus(servos.device(), DynamixelBusOptions{.retries = -1});
    ADD_FAILURE() << "negative retries accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "DynamixelBusOptions::retries: -1 is below 0");
  }
  EXPECT_THROW(DynamixelBus(servos.device(), DynamixelBusOptions{.baud_rate = 12345}),
               std::invalid_argument);
  EXPECT_THROW(DynamixelBus(servos.device(), DynamixelBusOptions{.status_return_level = 3}),
               std::invalid_argument);
}

TEST(Ax12SimPlugin, BadParametersAreClearErrors) {
  ComponentHost host(in_process());
  struct Case {
    std::map<std::string, ParameterValue> parameters;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {{{"faults", std::vector<std::string>{"2:melt"}}}, "expected ID:FAULT"},
      {{{"faults", std::vector<std::string>{"9:silent"}}}, "no servo with ID 9"},
      {{{"ids", std::vector<int64_t>{1, 1}}}, "ID 1 given twice"},
      {{{"ids", std::vector<int64_t>{}}}, "parameter 'ids' is empty"},
      {{{"ids", std::vector<int64_t>{254}}}, "ids"},
      {{{"initial_positions", std::vector<int64_t>{100}}}, "has 1 values for 2 servos"},
  };
  int index = 0;
  for (const Case& c : cases) {
    try {
      host.add(ax12_factory(),
               {.name = "servos" + std::to_string(index++), .parameters = c.parameters});
      ADD_FAILURE() << "no error, expected " << c.expected;
    } catch (const ComponentError& e) {
      EXPECT_NE(std::string(e.what()).find(c.expected), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace mocap::dynamixel
