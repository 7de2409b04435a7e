// What the one-hop benchmarks (transport_bench, security_bench) share: stamped messages of two
// sizes, the subscriber's record of what arrived, the publishing loop, and the publisher and
// subscriber components on kTopic.
#pragma once

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <mocap/component.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>
#include <sensor_msgs/msg/image.hpp>

namespace mocap::one_hop {

using Steady = std::chrono::steady_clock;

inline constexpr const char* kTopic = "/bench/hop";
inline constexpr int kWarmup = 50;
// Messages with this frame id only prove that the path is open both ways: a publisher of one
// DDS implementation may see its subscriber before that subscriber sees it, and a subscriber
// then misses what came before (launch_yaml/README.md). Not counted.
inline constexpr const char* kPrimingFrame = "priming";

inline int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Steady::now().time_since_epoch())
      .count();
}

template <class T>
void stamp(T& message) {
  int64_t ns = steady_ns();
  message.header().stamp().sec(static_cast<int32_t>(ns / 1000000000));
  message.header().stamp().nanosec(static_cast<uint32_t>(ns % 1000000000));
}

template <class T>
int64_t stamp_ns(const T& message) {
  return int64_t(message.header().stamp().sec()) * 1000000000 + message.header().stamp().nanosec();
}

// What a subscriber saw: one-way latencies (after the warm-up) and arrival times.
struct Received {
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<double> latencies_us;
  int count = 0;
  int64_t first_ns = 0, last_ns = 0;

  bool primed = false;  // a priming message arrived (not counted)

  template <class T>
  void add(const T& message) {
    int64_t now = steady_ns();
    std::lock_guard lock(mutex);
    if (message.header().frame_id() == kPrimingFrame) {
      primed = true;
      changed.notify_all();
      return;
    }
    if (count == 0) first_ns = now;
    last_ns = now;
    if (++count > kWarmup) latencies_us.push_back(double(now - stamp_ns(message)) / 1e3);
    changed.notify_all();
  }

  bool wait_for(int total, std::chrono::seconds timeout) {
    std::unique_lock lock(mutex);
    return changed.wait_for(lock, timeout, [&] { return count >= total; });
  }

  bool wait_primed(std::chrono::seconds timeout) {
    std::unique_lock lock(mutex);
    return changed.wait_for(lock, timeout, [&] { return primed; });
  }
};

inline Received received;  // in whichever process subscribes

// --- messages -------------------------------------------------------------------------

struct Size {
  std::string label;
  bool image;
  uint32_t width, height;  // image size, or fiducial count in width
  int latency_rate_hz;
  int latency_count;
  int throughput_count;
};

template <class T>
T prototype(const Size& size);

template <>
inline mocap_msgs::msg::FiducialArray prototype(const Size& size) {
  mocap_msgs::msg::FiducialArray array;
  array.header().frame_id("camera");
  for (uint32_t i = 0; i < size.width; ++i) {
    mocap_msgs::msg::Fiducial f;
    f.x(100.0f + float(i));
    f.y(200.0f - float(i));
    f.size(12);
    f.uncertainty(0.1f);
    array.fiducials().push_back(f);
  }
  return array;
}

template <>
inline sensor_msgs::msg::Image prototype(const Size& size) {
  sensor_msgs::msg::Image image;
  image.header().frame_id("camera");
  image.width(size.width);
  image.height(size.height);
  image.encoding("mono8");
  image.step(size.width);
  image.data(std::vector<uint8_t>(size_t(size.width) * size.height, 17));
  return image;
}

template <class T>
class BenchPublisher final : public mocap::Component {
 public:
  static void declare(mocap::ComponentSpec& spec) {
    spec.publishes<T>(kTopic, mocap::Qos::reliable(), "");
  }
  explicit BenchPublisher(mocap::Context& context) : Component(context) {
    publisher = create_publisher<T>(kTopic);
  }
  mocap::Publisher<T> publisher;
};

template <class T>
class BenchSubscriber final : public mocap::Component {
 public:
  static void declare(mocap::ComponentSpec& spec) {
    spec.subscribes<T>(kTopic, mocap::Qos::reliable(), "");
  }
  explicit BenchSubscriber(mocap::Context& context) : Component(context) {
    create_subscription<T>(kTopic, [](const T& message) { received.add(message); });
  }
};

template <class T>
constexpr mocap::ComponentFactory kPublisherFactory =
    mocap::make_component_factory<BenchPublisher<T>>("bench_publisher");
template <class T>
constexpr mocap::ComponentFactory kSubscriberFactory =
    mocap::make_component_factory<BenchSubscriber<T>>("bench_subscriber");

inline double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1, size_t(q * double(values.size())))];
}

// Calls `publish` for the warm-up and `count` messages, at `rate_hz` or as fast as possible
// when 0. `publish` makes, stamps and publishes one message, and returns its stamp.
template <class Publish>
int64_t publish_all(int count, int rate_hz, Publish publish) {
  auto period =
      rate_hz > 0 ? std::chrono::nanoseconds(1000000000 / rate_hz) : std::chrono::nanoseconds(0);
  auto next = Steady::now();
  int64_t first = 0;
  for (int i = 0; i < kWarmup + count; ++i) {
    if (rate_hz > 0) {
      next += period;
      std::this_thread::sleep_until(next);
    }
    int64_t stamped = publish();
    if (i == 0) first = stamped;
  }
  return first;
}

}  // namespace mocap::one_hop
