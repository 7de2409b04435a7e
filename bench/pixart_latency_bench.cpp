// Latency of the PixArt path through the runtime, from a camera sample's CAN frames written on
// the USB-CAN adaptor's pseudo-terminal to the robot poses received on /pixart/robots, beside
// the bare pseudo-terminal and the libraries alone, measured in the same run.
//   build/bin/pixart_latency_bench [--quick]
//
// This process plays the adaptor (SimulatedSlcanAdaptor answers the bridge's SLCAN commands on
// a PseudoTerminal) and hosts the real pixart_bridge and pixart_localizer plugins, with a
// recorder on /pixart/robots, in one ComponentHost without DDS. The frames are the simulator's
// (config/pixart/rig.yaml, scenes/two_robots.yaml), one camera sample at a time, 5 ms apart so
// that each sample's result is over before the next is written.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include <mocap/component_host.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/robot_pose_array.hpp>

#include "common/can_io/slcan.hpp"
#include "common/serial_io/serial_port.hpp"
#include "host/plugin_loader.hpp"
#include "pixart/pixart_bridge/camera_samples.hpp"
#include "pixart/pixart_bridge/pixart_bridge.hpp"
#include "pixart/pixart_localizer/pixart_localizer.hpp"
#include "pixart/pixart_rig/pixart_rig.hpp"
#include "sim/pixart_box_sim/pixart_box_simulator.hpp"
#include "sim/pixart_box_sim/pixart_scene.hpp"
#include "sim/pixart_box_sim/simulated_slcan_adaptor.hpp"

namespace {

using namespace mocap;
using Steady = std::chrono::steady_clock;
using Poses = mocap_msgs::msg::RobotPoseArray;

constexpr int kBitrate = 1000000;
// Between two camera samples: a sample's result takes well under a millisecond.
constexpr std::chrono::milliseconds kGap{5};

int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Steady::now().time_since_epoch())
      .count();
}

// The clock the runtime stamps with (mocap::Clock): the bridge stamps each frame with it when
// it reads the frame (the frames here carry no adaptor timestamps), and the localizer stamps
// its arrays with those stamps.
int64_t clock_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
      .count();
}

struct Summary {
  size_t samples = 0;
  double median_us = 0, p95_us = 0, max_us = 0;
};

size_t robots_in(const pixart::PixartScene& scene) {
  return static_cast<size_t>(std::count_if(
      scene.objects.begin(), scene.objects.end(),
      [](const auto& object) { return object.kind == pixart::SceneObject::Kind::Robot; }));
}

Summary summarize(std::vector<double> us) {
  if (us.empty()) return {};
  std::sort(us.begin(), us.end());
  auto at = [&](double q) {
    return us[std::min(us.size() - 1, static_cast<size_t>(q * us.size()))];
  };
  return {us.size(), at(0.5), at(0.95), us.back()};
}

// --- the bare pseudo-terminal -------------------------------------------------------------------

// `bytes` written on the master, until a reader blocked on the slave (the bridge's SerialPort)
// has all of them: the floor under the runtime's rows.
std::vector<double> bare_pty(const std::string& bytes, int samples) {
  serial::PseudoTerminal pty;
  serial::SerialPort port(pty.slave_path());
  const auto lines = static_cast<size_t>(std::count(bytes.begin(), bytes.end(), '\r'));
  std::vector<int64_t> arrived(static_cast<size_t>(samples));
  std::atomic<int> complete{0};
  std::jthread reader([&](std::stop_token stop) {
    char buffer[4096];
    size_t seen = 0;
    while (!stop.stop_requested() && complete < samples) {
      const size_t count = port.read(buffer, sizeof buffer, std::chrono::milliseconds(100));
      const int64_t now = steady_ns();
      seen += static_cast<size_t>(std::count(buffer, buffer + count, '\r'));
      if (count > 0 && seen % lines == 0) {
        arrived[seen / lines - 1] = now;
        complete.store(static_cast<int>(seen / lines), std::memory_order_release);
      }
    }
  });
  std::vector<double> latencies;
  for (int i = 0; i < samples; ++i) {
    // The reader is asleep in poll() again, as the bridge's is between samples.
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    const int64_t written = steady_ns();
    pty.write_all(bytes);
    while (complete.load(std::memory_order_acquire) <= i) {
      std::this_thread::sleep_for(std::chrono::microseconds(100));
    }
    latencies.push_back(static_cast<double>(arrived[static_cast<size_t>(i)] - written) / 1e3);
  }
  return latencies;
}

// --- the libraries alone ------------------------------------------------------------------------

struct LibraryResult {
  std::vector<double> latencies_us;
  size_t every_robot = 0;  // results holding every robot of the scene
};

// One camera sample's SLCAN text -> frames -> points -> localizer -> tracked robots, as the
// bridge and the localizer run them, without messages or threads between them.
LibraryResult libraries_alone(const pixart::Rig& rig, const pixart::PixartScene& scene,
                              double warmup_s, double seconds) {
  pixart::PixartBoxSimulator simulator(rig, scene);
  pixart::localization::RobotLocalizer localizer(rig);
  pixart::PixartDecoder decoder;
  pixart::CameraSampleAssembler assembler;
  can::SlcanParser parser;
  std::vector<pixart::PixartPoint> points;
  std::vector<Eigen::Vector2d> pixels;
  LibraryResult result;
  const double period = 1.0 / 270;
  for (double t = 0; t < warmup_s + seconds; t += period) {
    const auto stamp = static_cast<int64_t>(t * 1e9);
    const std::vector<can::CanFrame> frames = simulator.frames_at(t, stamp);
    for (size_t c = 0; c + 1 < frames.size(); c += 2) {
      const std::string text = can::encode_slcan(frames[c]) + can::encode_slcan(frames[c + 1]);
      const int64_t start = steady_ns();
      parser.feed(text, stamp);
      size_t robots = 0;
      for (const can::CanFrame& frame : parser.take_frames()) {
        points.clear();
        const auto camera = decoder.decode(frame, points);
        if (!camera) continue;
        const int half = static_cast<int>((frame.id - decoder.options().base_id) & 1u);
        const auto sample = assembler.add(*camera, half, frame.stamp_ns, points);
        if (!sample) continue;
        pixels.clear();
        for (const pixart::PixartPoint& p : sample->points) pixels.emplace_back(p.x, p.y);
        localizer.add_sample(rig.find_camera(sample->camera_id)->name, sample->stamp_ns, pixels);
        robots = localizer.tracked_robots(sample->stamp_ns).size();
      }
      const int64_t end = steady_ns();
      if (t < warmup_s) continue;
      result.latencies_us.push_back(static_cast<double>(end - start) / 1e3);
      result.every_robot += robots == robots_in(scene);
    }
  }
  return result;
}

// --- through the runtime ------------------------------------------------------------------------

// Every /pixart/robots array: when it arrived (steady clock), its stamp (mocap::Clock).
struct Arrival {
  int64_t received_ns = 0;
  int64_t stamp_ns = 0;
  size_t robots = 0;
};

class PoseRecorder final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.subscribes<Poses>("/pixart/robots", Qos::reliable(), "the localizer's output");
  }
  explicit PoseRecorder(Context& context) : Component(context) {
    create_subscription<Poses>("/pixart/robots", [this](const Poses& poses) {
      const int64_t now = steady_ns();
      std::lock_guard lock(mutex);
      arrivals.push_back({now, to_nanoseconds(poses.header().stamp()), poses.robots().size()});
    });
  }
  std::mutex mutex;
  std::vector<Arrival> arrivals;
};

// The adaptor's end of the pseudo-terminal, played on the calling thread.
class Adaptor {
 public:
  struct Write {
    int64_t steady_ns = 0;
    int64_t clock_ns = 0;
  };

  const std::string& device() const { return pty_.slave_path(); }

  // Whether the bridge has opened the channel at the box's bitrate: frames would pass.
  bool channel_open() const {
    return adaptor_.is_open() && adaptor_.bitrate() == kBitrate && pty_.peer_connected();
  }

  // Answers the bridge's commands until `deadline`.
  void serve_until(Steady::time_point deadline) {
    char buffer[256];
    for (auto left = deadline - Steady::now(); left > Steady::duration::zero();
         left = deadline - Steady::now()) {
      const size_t count =
          pty_.read(buffer, sizeof buffer, std::chrono::ceil<std::chrono::milliseconds>(left));
      if (count == 0) continue;
      const std::string answers = adaptor_.feed(std::string_view(buffer, count));
      if (!answers.empty()) pty_.write_all(answers);
    }
  }

  // Sends `frames` to the bridge; returns the times taken just before the first byte went out.
  Write write(const std::vector<can::CanFrame>& frames) {
    std::string bytes;
    // Without the adaptor's timestamps, which the bridge asks for: their milliseconds would
    // put a sample's stamp before its write. The bridge stamps each frame when it reads it, so
    // a stamp taken after the write's mocap::Clock time cannot be earlier.
    for (const can::CanFrame& frame : frames) bytes += can::encode_slcan(frame);
    Write write;
    write.clock_ns = clock_ns();
    write.steady_ns = steady_ns();
    pty_.write_all(bytes);
    return write;
  }

 private:
  serial::PseudoTerminal pty_;
  pixart::SimulatedSlcanAdaptor adaptor_;
};

struct RuntimeResult {
  std::vector<double> latencies_us;
  size_t written = 0;
  size_t unanswered = 0;    // no array reflected the sample before the end
  size_t stamp_behind = 0;  // the sample did not advance the array's stamp (see match())
  size_t every_robot = 0;   // timed samples whose array holds every robot of the scene
};

// A sample written at W (mocap::Clock) is reflected by the first array stamped at or after W,
// whatever the publish rate:
//  - the bridge stamps a sample with the time it read it, after W. The localizer stamps an
//    array with the newest stamp at which it read a tracked robot (the newest sample's stamp
//    while none is tracked); it reads every robot from all cameras' fresh views at each sample.
//    So an array stamped at or after W was built after a sample read after W was used, and
//    samples reach the localizer in the order they were written, each long before the next
//    is written: it was built after this one was used.
//  - an array stamped before W was built before this sample was used, whenever it arrives.
// Latency = that array's arrival − the write, on the steady clock.
// A sample in which no tracked robot was read leaves the stamp where it was; the first array
// stamped at or after W is then one built after a later sample, and the latency would be
// overstated. Publishing after every sample tells: a sample's own array then carries the
// sample's stamp, before the next write; a sample whose first array stamped at or after W is
// stamped after the next write is counted (stamp_behind), not timed. With the timer one array
// covers several samples and the check cannot apply; the count of the other row shows how rare such
// samples are in this scene.
RuntimeResult match(const std::vector<Adaptor::Write>& writes, const std::vector<Arrival>& arrivals,
                    bool one_array_per_sample, size_t robots) {
  RuntimeResult result;
  result.written = writes.size();
  size_t from = 0;
  for (size_t i = 0; i < writes.size(); ++i) {
    while (from < arrivals.size() && arrivals[from].received_ns <= writes[i].steady_ns) ++from;
    size_t j = from;
    while (j < arrivals.size() && arrivals[j].stamp_ns < writes[i].clock_ns) ++j;
    if (j == arrivals.size()) {
      ++result.unanswered;
      continue;
    }
    if (one_array_per_sample && i + 1 < writes.size() &&
        arrivals[j].stamp_ns >= writes[i + 1].clock_ns) {
      ++result.stamp_behind;
      continue;
    }
    result.latencies_us.push_back(
        static_cast<double>(arrivals[j].received_ns - writes[i].steady_ns) / 1e3);
    result.every_robot += arrivals[j].robots == robots;
  }
  return result;
}

RuntimeResult through_runtime(PluginLoader& loader, const std::string& config,
                              const pixart::Rig& rig, const pixart::PixartScene& scene,
                              double publish_rate_hz, double warmup_s, double seconds) {
  Adaptor adaptor;  // outlives the host: the bridge closes the channel when it is destroyed
  ComponentHost host({.name = "pixart_latency_bench", .threads = 2, .dds = {.enabled = false}});
  // As launch_yaml/pixart_localization.yaml configures them.
  host.add(*loader.load("pixart_bridge").factory,
           {.name = "bridge",
            .parameters = {{"source", std::string("slcan")},
                           {"device", adaptor.device()},
                           {"bitrate", kBitrate},
                           {"camera_names", std::vector<std::string>{"camera0", "camera1",
                                                                     "camera2", "camera3"}}}});
  host.add(*loader.load("pixart_localizer").factory,
           {.name = "localizer",
            .parameters = {{"rig", config + "/rig.yaml"}, {"publish_rate_hz", publish_rate_hz}}});
  auto& recorder = static_cast<PoseRecorder&>(
      host.add(make_component_factory<PoseRecorder>("recorder"), {.name = "recorder"}));
  host.start();

  const auto give_up = Steady::now() + std::chrono::seconds(10);
  while (!adaptor.channel_open()) {
    if (Steady::now() > give_up) throw std::runtime_error("the bridge never opened the channel");
    adaptor.serve_until(Steady::now() + std::chrono::milliseconds(10));
  }

  pixart::PixartBoxSimulator simulator(rig, scene);
  std::vector<Adaptor::Write> writes;
  const auto start = Steady::now();
  for (double t = 0; t < warmup_s + seconds;
       t = std::chrono::duration<double>(Steady::now() - start).count()) {
    // Every camera sees the scene at t, as the box samples them together; they are sent one
    // after the other.
    const std::vector<can::CanFrame> frames = simulator.frames_at(t);
    for (size_t c = 0; c + 1 < frames.size(); c += 2) {
      const Adaptor::Write write = adaptor.write({frames[c], frames[c + 1]});
      if (t >= warmup_s) writes.push_back(write);
      adaptor.serve_until(Steady::time_point(std::chrono::nanoseconds(write.steady_ns)) + kGap);
    }
  }
  // The last sample's array, and a timer tick.
  adaptor.serve_until(Steady::now() + std::chrono::milliseconds(50));
  host.stop();
  std::lock_guard lock(recorder.mutex);
  return match(writes, recorder.arrivals, publish_rate_hz == 0, robots_in(scene));
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  const double warmup_s = quick ? 0.5 : 1.0;  // robots found, caches and queues warm
  const double runtime_s = quick ? 1.0 : 10.0;
  const int pty_samples = quick ? 300 : 2000;
  setenv("MOCAP_LOG_LEVEL", "warn", 0);  // the components' start and stop lines

  const std::string config = MOCAP_CONFIG_DIR "/pixart";
  const pixart::Rig rig = pixart::load_rig(config + "/rig.yaml");
  const pixart::PixartScene scene =
      pixart::load_pixart_scene(config + "/scenes/two_robots.yaml", rig);
  PluginLoader loader;

  // One camera sample as the adaptor sends it: two frames, two SLCAN lines.
  pixart::PixartBoxSimulator simulator(rig, scene);
  const std::vector<can::CanFrame> frames = simulator.frames_at(0);
  const std::string sample_text = can::encode_slcan(frames[0]) + can::encode_slcan(frames[1]);

  const std::vector<double> pty = bare_pty(sample_text, pty_samples);
  const LibraryResult libraries = libraries_alone(rig, scene, warmup_s, quick ? 1.0 : 5.0);
  const RuntimeResult timer =
      through_runtime(loader, config, rig, scene, 50.0, warmup_s, runtime_s);
  const RuntimeResult every = through_runtime(loader, config, rig, scene, 0.0, warmup_s, runtime_s);

  fmt::print(
      "PixArt latency: one camera sample's 2 CAN frames written on the adaptor's pseudo-terminal "
      "-> robot poses received on /pixart/robots; samples {} ms apart, two_robots.yaml, 2 "
      "executor threads\n\n",
      kGap.count());
  fmt::print("| path | samples | median µs | p95 µs | max µs |\n|---|---:|---:|---:|---:|\n");
  auto row = [](const std::string& name, const std::vector<double>& latencies) {
    const Summary s = summarize(latencies);
    fmt::print("| {} | {} | {:.1f} | {:.1f} | {:.1f} |\n", name, s.samples, s.median_us, s.p95_us,
               s.max_us);
  };
  row("runtime, publish_rate_hz 50 (default): pty -> bridge -> localizer -> subscriber",
      timer.latencies_us);
  row("runtime, publish_rate_hz 0 (after every sample): pty -> bridge -> localizer -> subscriber",
      every.latencies_us);
  row("bare pty: 2 SLCAN lines, master -> reader blocked on the slave", pty);
  row("libraries alone: SLCAN text -> decode -> localize one sample", libraries.latencies_us);
  const auto percent = [](size_t part, size_t whole) {
    return 100.0 * static_cast<double>(part) / static_cast<double>(std::max<size_t>(whole, 1));
  };
  fmt::print(
      "\nThe 50 Hz row includes the wait for the localizer's next tick (0-20 ms).\n"
      "Samples written after the warm-up: {} at 50 Hz, {} at 0; without an array reflecting them: "
      "{}, {}; at 0, not timed because their own array kept an older stamp: {}.\n"
      "Results holding both robots: {:.1f} % at 50 Hz, {:.1f} % at 0, {:.1f} % of the libraries "
      "alone.\n",
      timer.written, every.written, timer.unanswered, every.unanswered, every.stamp_behind,
      percent(timer.every_robot, timer.latencies_us.size()),
      percent(every.every_robot, every.latencies_us.size()),
      percent(libraries.every_robot, libraries.latencies_us.size()));
  return 0;
}
