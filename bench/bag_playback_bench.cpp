// Playback timing at rate 1: how far from its recorded offset each message is handed over
// (the playback library alone) and received (mocap_bag play in another process, a subscriber
// here, over DDS), from an MCAP bag and from a sqlite3 bag of the same messages, against a bare
// sleep_until loop on the same schedule, in the same run.
//   build/bin/bag_playback_bench
#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <mocap/bag/bag_reader.hpp>
#include <mocap/bag/bag_writer.hpp>
#include <mocap/bag/playback.hpp>
#include <mocap/component_host.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>

#include "test/test_support.hpp"

namespace {

using namespace mocap;
using SteadyClock = std::chrono::steady_clock;
using mocap_msgs::msg::FiducialArray;

constexpr int kMessages = 1000;
constexpr int64_t kPeriodNs = 5'000'000;  // 200 Hz, with up to ±1 ms of jitter

std::string row(const std::string& path, std::vector<double> v) {
  std::sort(v.begin(), v.end());
  auto at = [&](double q) { return v[static_cast<size_t>(q * static_cast<double>(v.size() - 1))]; };
  const auto within = std::count_if(v.begin(), v.end(), [](double e) { return e <= 1000; });
  return fmt::format("| {} | {} | {:.1f} | {:.1f} | {:.1f} | {:.1f} % |\n", path, v.size(), at(0.5),
                     at(0.99), v.back(),
                     100.0 * static_cast<double>(within) / static_cast<double>(v.size()));
}

// How far each message's time is from its recorded offset, in µs, once the path's constant
// delay (the median over all messages) is taken out: a message that takes 300 µs through DDS is
// on time if every message does. (Measured from the first message alone, whatever that one
// message's delivery cost, the first sample on a new connection, is charged to all the others.)
std::vector<double> errors(const std::vector<int64_t>& stamps,
                           const std::vector<SteadyClock::time_point>& times) {
  std::vector<double> late;
  for (size_t i = 0; i < std::min(stamps.size(), times.size()); ++i) {
    const double due = static_cast<double>(stamps[i] - stamps[0]) / 1e3;
    const double got = std::chrono::duration<double, std::micro>(times[i] - times[0]).count();
    late.push_back(got - due);
  }
  std::vector<double> sorted = late;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2),
                   sorted.end());
  const double delay = sorted.empty() ? 0 : sorted[sorted.size() / 2];
  for (double& value : late) value = std::abs(value - delay);
  return late;
}

std::vector<SteadyClock::time_point> received_times;
std::mutex received_mutex;

class Timer final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.subscribes<FiducialArray>("/paced", Qos::reliable(), "");
  }
  explicit Timer(Context& context) : Component(context) {
    create_subscription<FiducialArray>("/paced", [](const FiducialArray&) {
      std::lock_guard lock(received_mutex);
      received_times.push_back(SteadyClock::now());
    });
  }
};

}  // namespace

int main() {
  test::TempDir dir;
  std::mt19937 random(1);
  std::uniform_int_distribution<int64_t> jitter(-1'000'000, 1'000'000);
  std::vector<int64_t> stamps;
  for (int i = 0; i < kMessages; ++i) {
    stamps.push_back(1'700'000'000'000'000'000 + i * kPeriodNs + jitter(random));
  }
  const std::vector<std::string> storages = {"mcap", "sqlite3"};
  for (const std::string& storage : storages) {
    bag::BagWriterOptions options;
    options.storage = storage;
    bag::BagWriter writer((dir / storage).string(), options);
    const uint32_t id =
        writer.add_topic({"/paced", "mocap_msgs/msg/FiducialArray", "cdr", {Qos::reliable()}, 0});
    const MessageType& type = message_type<FiducialArray>();
    for (int i = 0; i < kMessages; ++i) {
      FiducialArray array;
      array.header().stamp().sec(i);
      std::vector<uint8_t> bytes(type.serialized_size(&array));
      bytes.resize(type.serialize(&array, bytes));
      writer.write(id, stamps[static_cast<size_t>(i)], bytes);
    }
    writer.close();
  }
  std::sort(stamps.begin(), stamps.end());

  // Reference: the same schedule slept through with nothing else.
  std::vector<SteadyClock::time_point> slept;
  const auto start = SteadyClock::now();
  for (int64_t stamp : stamps) {
    std::this_thread::sleep_until(start + std::chrono::nanoseconds(stamp - stamps[0]));
    slept.push_back(SteadyClock::now());
  }

  fmt::print(
      "## Playback timing at rate 1\n\n"
      "{} messages recorded 5 ms apart with up to ±1 ms of jitter; each message's offset from "
      "the first, handed over or received, against its recorded offset, less the path's "
      "constant delay (the median difference) (the target: within 1 ms).\n\n"
      "| path | messages | median µs | p99 µs | max µs | within 1 ms |\n"
      "|---|---:|---:|---:|---:|---:|\n",
      kMessages);
  fmt::print("{}", row("reference: sleep_until on the same schedule", errors(stamps, slept)));
  const std::string domain = std::to_string(test::test_domain(90));
  setenv("MOCAP_DOMAIN_ID", domain.c_str(), 1);
  for (const std::string& storage : storages) {
    // The playback library: when each message is handed to the publisher.
    std::vector<SteadyClock::time_point> handed;
    bag::BagReader reader((dir / storage).string());
    std::atomic<bool> stop{false};
    bag::play(
        reader, {}, [&](const bag::BagMessage&) { handed.push_back(SteadyClock::now()); }, stop);
    fmt::print("{}", row(fmt::format("{} bag: mocap::bag::play, handed to the publisher", storage),
                         errors(stamps, handed)));

    // mocap_bag play in its own process, received here over DDS.
    {
      std::lock_guard lock(received_mutex);
      received_times.clear();
    }
    ComponentHost host({.name = "bench", .threads = 2, .dds = {}});
    host.add(make_component_factory<Timer>("timer"), {.name = "timer"});
    host.start();
    auto [code, output] =
        test::run_command({(test::bin_dir() / "mocap_bag").string(), "play",
                           (dir / storage).string(), "--delay", "1.5"},
                          {{"MOCAP_DOMAIN_ID", domain}}, std::chrono::seconds(60));
    if (code != 0) fmt::print(stderr, "mocap_bag play failed:\n{}", output);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    host.stop();
    std::lock_guard lock(received_mutex);
    fmt::print("{}", row(fmt::format("{} bag: mocap_bag play → DDS → subscriber in another process",
                                     storage),
                         errors(stamps, received_times)));
    if (received_times.size() != stamps.size()) {
      fmt::print("({} bag: {} of {} messages received)\n", storage, received_times.size(),
                 stamps.size());
    }
  }
  return 0;
}
