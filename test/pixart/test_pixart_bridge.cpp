// The pixart_bridge plugin through the runtime: SLCAN frames written on a pseudo-terminal (a
// simulated USB adaptor) come out as per-camera fiducial arrays and raw points; the adaptor
// unplugged and plugged back in; a candump log replayed.
#include <gtest/gtest.h>

#include <condition_variable>
#include <filesystem>
#include <mutex>

#include <mocap/component_host.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>
#include <mocap_msgs/msg/pixart_raw_point_array.hpp>

#include "common/can_io/candump_log.hpp"
#include "common/can_io/slcan.hpp"
#include "common/serial_io/serial_port.hpp"
#include "host/plugin_loader.hpp"
#include "pixart/pixart_bridge/pixart_bridge.hpp"
#include "test/test_support.hpp"

namespace mocap::pixart {
namespace {

using Fiducials = mocap_msgs::msg::FiducialArray;
using Raw = mocap_msgs::msg::PixartRawPointArray;

// Collects what the bridge publishes for camera "left" (camera 1) and on /pixart/raw.
class Collector final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.subscribes<Fiducials>("/pixart/left/fiducials", Qos::reliable(), "");
    spec.subscribes<Raw>("/pixart/raw", Qos::reliable(), "");
  }
  explicit Collector(Context& context) : Component(context) {
    create_subscription<Fiducials>("/pixart/left/fiducials", [this](const Fiducials& array) {
      std::lock_guard lock(mutex);
      arrays.push_back(array);
      arrived.notify_all();
    });
    create_subscription<Raw>("/pixart/raw", [this](const Raw& raw) {
      std::lock_guard lock(mutex);
      raw_points += raw.points().size();
      arrived.notify_all();
    });
  }
  bool wait_for(size_t count, std::chrono::seconds timeout) {
    std::unique_lock lock(mutex);
    return arrived.wait_for(lock, timeout, [&] { return arrays.size() >= count; });
  }
  // The bridge publishes a read's raw points after the samples they complete.
  bool wait_for_raw_points(size_t count, std::chrono::seconds timeout) {
    std::unique_lock lock(mutex);
    return arrived.wait_for(lock, timeout, [&] { return raw_points >= count; });
  }
  std::mutex mutex;
  std::condition_variable arrived;
  std::vector<Fiducials> arrays;
  size_t raw_points = 0;
};

const ComponentFactory& bridge_factory() {
  static PluginLoader loader;
  return *loader.load("pixart_bridge").factory;
}

// Both frames of one sample of camera 1 (box 0): points at (100 + i, 200) in slots 0 and 2.
std::string sample_of_camera_1(uint16_t i) {
  std::string bytes;
  bytes += can::encode_slcan(
      encode_pixart_frame(0x100, 1, 0, {std::array<uint16_t, 2>{uint16_t(100 + i), 200}, {}}));
  bytes += can::encode_slcan(
      encode_pixart_frame(0x100, 1, 1, {std::array<uint16_t, 2>{uint16_t(500 + i), 600}, {}}));
  return bytes;
}

HostOptions in_process() { return {.name = "test", .threads = 2, .dds = {.enabled = false}}; }

TEST(PixartBridge, SlcanFramesBecomeFiducialsAndTheAdaptorMayBeUnplugged) {
  test::TempDir dir;
  auto adaptor = std::make_unique<serial::PseudoTerminal>();
  // The bridge opens a stable name, as udev gives a real adaptor; replugging re-points it.
  std::filesystem::path device = dir / "ttyPIXART";
  std::filesystem::create_symlink(adaptor->slave_path(), device);

  ComponentHost host(in_process());
  host.add(bridge_factory(),
           {.name = "bridge",
            .parameters = {{"device", device.string()},
                           {"camera_names", std::vector<std::string>{"right", "left"}}}});
  auto& collector = static_cast<Collector&>(
      host.add(make_component_factory<Collector>("collector"), {.name = "collector"}));
  host.start();

  // The bridge opens the channel itself: close, 1 Mbit/s, open.
  std::string commands;
  char buffer[256];
  for (int i = 0; i < 50 && commands.find("O\r") == std::string::npos; ++i) {
    size_t n = adaptor->read(buffer, sizeof buffer, std::chrono::milliseconds(100));
    commands.append(buffer, n);
  }
  EXPECT_EQ(commands, "C\rS8\rZ1\rO\r");

  // Frames split at every byte boundary, garbage and an error bell among them.
  std::string stream = sample_of_camera_1(0) + "tZZZ\r\a" + sample_of_camera_1(1);
  for (char c : stream) adaptor->write_all(std::string(1, c));
  ASSERT_TRUE(collector.wait_for(2, std::chrono::seconds(10)));
  {
    std::lock_guard lock(collector.mutex);
    const Fiducials& first = collector.arrays[0];
    EXPECT_EQ(first.header().frame_id(), "left");
    ASSERT_EQ(first.fiducials().size(), 2u);
    EXPECT_EQ(first.fiducials()[0].x(), 100);
    EXPECT_EQ(first.fiducials()[1].x(), 500);
    EXPECT_EQ(first.fiducials()[1].y(), 600);
    EXPECT_EQ(collector.arrays[1].fiducials()[0].x(), 101);
  }

  // Unplugged: the master end goes away. Plugged in again as a new device under the same
  // name; the bridge reopens it, opens the channel again and carries on.
  adaptor.reset();
  adaptor = std::make_unique<serial::PseudoTerminal>();
  std::filesystem::remove(device);
  std::filesystem::create_symlink(adaptor->slave_path(), device);
  commands.clear();
  for (int i = 0; i < 100 && commands.find("O\r") == std::string::npos; ++i) {
    size_t n = adaptor->read(buffer, sizeof buffer, std::chrono::milliseconds(100));
    commands.append(buffer, n);
  }
  EXPECT_NE(commands.find("S8\rZ1\rO\r"), std::string::npos) << commands;
  adaptor->write_all(sample_of_camera_1(2));
  ASSERT_TRUE(collector.wait_for(3, std::chrono::seconds(10)));
  {
    std::lock_guard lock(collector.mutex);
    EXPECT_EQ(collector.arrays[2].fiducials()[0].x(), 102);
  }
  EXPECT_TRUE(collector.wait_for_raw_points(6, std::chrono::seconds(10)));
  host.stop();
  EXPECT_EQ(collector.raw_points, 6u);
}

TEST(PixartBridge, ReplaysACandumpLog) {
  test::TempDir dir;
  std::string log;
  for (uint16_t i = 0; i < 20; ++i) {
    for (int half = 0; half < 2; ++half) {
      can::CandumpRecord record;
      record.stamp_ns = 1'700'000'000'000'000'000 + i * 3'700'000LL;  // 270 Hz
      record.interface = "can0";
      record.frame = encode_pixart_frame(
          0x100, 1, half, {std::array<uint16_t, 2>{uint16_t(10 * i), 700}, {}}, record.stamp_ns);
      log += can::format_candump_line(record) + "\n";
    }
  }
  log += "(1700000000.100000) can0 7FF#00\n";  // an unknown ID, counted
  test::write_file(dir / "bus.log", log);
  ComponentHost host(in_process());
  host.add(bridge_factory(),
           {.name = "bridge",
            .parameters = {{"source", std::string("candump")},
                           {"file", (dir / "bus.log").string()},
                           {"recorded_timing", false},
                           {"camera_names", std::vector<std::string>{"right", "left"}}}});
  auto& collector = static_cast<Collector&>(
      host.add(make_component_factory<Collector>("collector"), {.name = "collector"}));
  host.start();
  ASSERT_TRUE(collector.wait_for(20, std::chrono::seconds(10)));
  host.stop();
  std::lock_guard lock(collector.mutex);
  ASSERT_EQ(collector.arrays.size(), 20u);
  for (uint16_t i = 0; i < 20; ++i) {
    ASSERT_EQ(collector.arrays[i].fiducials().size(), 2u);
    EXPECT_EQ(collector.arrays[i].fiducials()[0].x(), 10 * i);
  }
}

TEST(PixartBridge, BadParametersAreClearErrors) {
  test::TempDir dir;
  test::write_file(dir / "bad.log", "(1.000000) can0 100#0011\nnot a candump line\n");
  ComponentHost host(in_process());
  try {
    host.add(bridge_factory(), {.name = "bridge",
                                .parameters = {{"source", std::string("candump")},
                                               {"file", (dir / "bad.log").string()}}});
    ADD_FAILURE() << "no error";
  } catch (const ComponentError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.log:2"), std::string::npos) << e.what();
  }
  try {
    host.add(bridge_factory(), {.name = "bridge2", .parameters = {{"source", std::string("usb")}}});
    ADD_FAILURE() << "no error";
  } catch (const ComponentError& e) {
    EXPECT_NE(std::string(e.what()).find("expected slcan, socketcan or candump"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace mocap::pixart
