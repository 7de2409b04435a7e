// pixart_box_sim: the simulated PixArt camera box (pixart_box_simulator.hpp), the embedded
// default when no box is attached. It writes real CAN frames, so that the real pixart_bridge
// code path runs:
//   - output "pty": it is a USB–CAN adaptor on a pseudo-terminal, speaking SLCAN
//     (simulated_slcan_adaptor.hpp). It answers the host's commands and, while the host has the
//     channel open at the box's bitrate, sends every sample's frames at real time. device_link
//     gives the pseudo-terminal a fixed name for the bridge's `device` parameter.
//   - output "candump": it writes duration_s of scene time to a `candump -L` log as fast as it
//     can (to FILE.partial, renamed to FILE when complete), for the bridge's candump source.
//
// Scene time starts when the component is created and follows the steady clock: sample k is
// sent at start + k / rate_hz. Ground truth, truth_rate_hz times per second of scene time:
//   - pty: on /pixart/ground_truth, stamped with the wall-clock time now() at which it was
//     computed, so a consumer pairs it with the bridge's fiducials (stamped with the adaptor's
//     timestamps, the sample's time, or when read if the host did not ask for them) by stamp;
//   - candump: in FILE.truth.csv (candump_recording.hpp), stamped on the log's time scale, so
//     the poses localized from a replay of FILE pair with it by stamp.
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include <mocap/component.hpp>
#include <mocap/config_files.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/robot_pose_array.hpp>

#include "common/can_io/slcan.hpp"
#include "common/serial_io/device_link.hpp"
#include "common/serial_io/serial_port.hpp"
#include "common/topics/graph_topics.hpp"
#include "pixart/pixart_rig/pixart_rig.hpp"
#include "sim/pixart_box_sim/candump_recording.hpp"
#include "sim/pixart_box_sim/pixart_box_simulator.hpp"
#include "sim/pixart_box_sim/pixart_scene.hpp"
#include "sim/pixart_box_sim/sample_schedule.hpp"
#include "sim/pixart_box_sim/simulated_slcan_adaptor.hpp"

namespace mocap::pixart {
namespace {

namespace fs = std::filesystem;
using Steady = std::chrono::steady_clock;

constexpr const char* kTruthFrame = "world";
// The adaptor thread checks for shutdown at least this often while nothing else wakes it.
constexpr std::chrono::milliseconds kLongestWait{50};
// How far behind the player, descheduled, still sends every sample when frames carry
// timestamps (a real adaptor's buffer holds about this much of a busy bus).
constexpr double kCatchUp_s = 0.1;
// A host that stops reading fills the pty's buffer; the box then drops the sample instead of
// holding up the next ones for long.
constexpr std::chrono::milliseconds kPtyWriteTimeout{200};

int64_t wall_clock_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// The simulator's options with what only the plugin reads.
struct Settings : PixartBoxSimulatorOptions {
  std::string rig = mocap::config_file("pixart/rig.yaml");
  std::string scene = mocap::config_file("pixart/scenes/two_robots.yaml");
  std::string output = "pty";
  std::string device_link;
  std::string file;
  double duration_s = 10.0;
  double start_stamp_s = 0.0;
  double rate_hz = 270.0;
  int bitrate = 1000000;
  double truth_rate_hz = 50.0;
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("rig", "rig file: cameras, LED plane, robots' LED layouts (config/pixart/README.md)",
             &Settings::rig)
        .path()
        .add("scene",
             "scene file: robots' trajectories, calibration boards (config/pixart/README.md)",
             &Settings::scene)
        .path()
        .add("output",
             "pty (a simulated SLCAN adaptor on a pseudo-terminal) or candump (a log file)",
             &Settings::output)
        .add("device_link",
             "pty: symbolic link to create to the pseudo-terminal (replacing an older link), "
             "for the bridge's `device`; empty = none (the log names the pty)",
             &Settings::device_link)
        .path()
        .add("file", "candump: the log to write", &Settings::file)
        .path()
        .add("duration_s", "candump: scene time to write, seconds", &Settings::duration_s)
        .range(0.001, 1e6)
        .add("start_stamp_s",
             "candump: receive time of the first sample, seconds since the Unix epoch; "
             "0 = now",
             &Settings::start_stamp_s)
        .range(0, 4e9)
        .add("rate_hz", "samples per second, all cameras at once", &Settings::rate_hz)
        .range(1, 10000)
        .add("bitrate",
             "pty: the box's CAN bitrate; the adaptor passes frames only when the host "
             "opened the channel at it",
             &Settings::bitrate)
        .range(10000, 1000000)
        .add("base_id", "CAN ID of camera 0, points 0-1", &Settings::base_id)
        .range(0, 0x7FF)
        .add("noise_px",
             "Gaussian noise on each coordinate before rounding, pixels (sigma); 0 = none",
             &Settings::noise_px)
        .range(0, 100)
        .add("seed", "seed of the noise", &Settings::seed)
        .range(0, 2147483647)
        .add("truth_rate_hz",
             "ground truth per second of scene time (pty: /pixart/ground_truth messages; "
             "candump: rows of FILE.truth.csv); 0 = none",
             &Settings::truth_rate_hz)
        .range(0, 1000);

class PixartBoxSim final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Simulated PixArt camera box: robots carrying IR LEDs move on the floor under the "
        "ceiling cameras; each camera's LEDs are sent as CAN frames at the sensor's rate, as an "
        "SLCAN USB-CAN adaptor on a pseudo-terminal (for pixart_bridge source: slcan) or into a "
        "candump -L log. Publishes the robots' true poses.");
    kParameters.declare(spec);
    spec.publishes<mocap_msgs::msg::RobotPoseArray>(
        topics::kPixartGroundTruth, Qos::reliable(),
        "pty output: every robot's true floor pose (x, y, theta), frame id world, stamped with "
        "the wall-clock time it describes");
  }

  explicit PixartBoxSim(Context& context) : Component(context) {
    if (settings_.output != "pty" && settings_.output != "candump") {
      throw std::invalid_argument("parameter 'output' is '" + settings_.output +
                                  "'; expected pty or candump");
    }
    Rig rig = load_rig(settings_.rig);
    PixartScene scene = load_pixart_scene(settings_.scene, rig);
    const size_t cameras = rig.cameras.size(), objects = scene.objects.size();
    simulator_ = std::make_unique<PixartBoxSimulator>(std::move(rig), std::move(scene), settings_);
    scene_start_ = Steady::now();
    scene_start_wall_ns_ = wall_clock_ns();

    if (settings_.output == "candump") {
      start_log(cameras, objects);
      return;
    }
    // Checks the bitrate: throws, naming the supported ones, for any other.
    can::slcan_open_commands(settings_.bitrate);
    truths_ = create_publisher<mocap_msgs::msg::RobotPoseArray>(topics::kPixartGroundTruth);
    pty_.emplace(serial::PseudoTerminalOptions{.write_timeout = kPtyWriteTimeout});
    const std::string link = settings_.device_link;
    if (!link.empty()) {
      device_link_.emplace(link, pty_->slave_path());
    }
    log().info("simulated SLCAN adaptor on {}{}: {} cameras, {} objects, {} Hz, {} bit/s",
               pty_->slave_path(), link.empty() ? "" : " (link " + link + ")", cameras, objects,
               settings_.rate_hz, settings_.bitrate);
    if (const double truth_rate = settings_.truth_rate_hz; truth_rate > 0) {
      create_timer(std::chrono::duration_cast<std::chrono::nanoseconds>(
                       std::chrono::duration<double>(1 / truth_rate)),
                   [this] { publish_truth(); });
    }
    create_worker("adaptor", [this](std::stop_token stop) { play_adaptor(stop); });
  }

  ~PixartBoxSim() override {
    device_link_.reset();
    if (pty_) {
      pty_->close_master();
      const PixartBoxSimulatorStats& s = simulator_->stats();
      log().info(
          "{} samples sent, {} skipped (late), {} held back (channel closed or no host), {} "
          "failed writes; {} points, {} beyond the sensors' 4; {} of {} host commands refused",
          sent_, skipped_, held_back_, failed_writes_, s.points, s.excess_points,
          adaptor_.stats().refused, adaptor_.stats().commands);
    }
  }

 private:
  // --- candump output ------------------------------------------------------------------------

  void start_log(size_t cameras, size_t objects) {
    const std::string file = settings_.file;
    if (file.empty()) {
      throw std::invalid_argument("parameter 'file' is empty; output candump needs it");
    }
    const std::string partial = file + ".partial";
    open_for_writing(log_stream_, partial);
    const double truth_rate = settings_.truth_rate_hz;
    const std::string truth_file = truth_rate > 0 ? file + ".truth.csv" : std::string();
    if (!truth_file.empty()) open_for_writing(truth_stream_, truth_file + ".partial");
    const double start_s = settings_.start_stamp_s;
    CandumpRecordingOptions options{
        .duration_s = settings_.duration_s,
        .rate_hz = settings_.rate_hz,
        .start_ns =
            start_s > 0 ? static_cast<int64_t>(std::llround(start_s * 1e9)) : wall_clock_ns(),
        .truth = truth_file.empty() ? nullptr : &truth_stream_,
        .truth_rate_hz = truth_rate};
    log().info("writing {} s of {} cameras, {} objects at {} Hz to {}{}", options.duration_s,
               cameras, objects, settings_.rate_hz, file,
               truth_file.empty() ? "" : ", ground truth to " + truth_file);
    create_worker("candump log", [this, options, file, partial, truth_file](std::stop_token stop) {
      try {
        const uint64_t frames = write_candump_recording(*simulator_, log_stream_, options, stop);
        log_stream_.close();
        truth_stream_.close();
        if (stop.stop_requested()) {
          log().warn("stopped after {} frames; the incomplete log stays in {}", frames, partial);
          return;
        }
        // The truth first: whoever waits for FILE finds its truth there too.
        if (!truth_file.empty()) fs::rename(truth_file + ".partial", truth_file);
        fs::rename(partial, file);
        log().info("wrote {} frames ({} samples) to {}", frames,
                   SampleSchedule(options.rate_hz).samples_before(options.duration_s), file);
      } catch (const std::exception& e) {
        log().error("{}: {}", partial, e.what());
      }
    });
  }

  static void open_for_writing(std::ofstream& stream, const std::string& path) {
    stream.open(path, std::ios::out | std::ios::trunc);
    if (!stream) throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
  }

  // --- pty output ----------------------------------------------------------------------------

  double scene_time() const {
    return std::chrono::duration<double>(Steady::now() - scene_start_).count();
  }

  // Plays the adaptor until stopped: answers the host's commands as they come and sends each
  // sample when its time comes.
  void play_adaptor(std::stop_token stop) {
    const SampleSchedule schedule(settings_.rate_hz);
    uint64_t next = 0;
    char buffer[512];
    while (!stop.stop_requested()) {
      const auto due_at = scene_start_ + std::chrono::duration_cast<Steady::duration>(
                                             std::chrono::duration<double>(schedule.time_of(next)));
      const auto wait =
          std::clamp(std::chrono::ceil<std::chrono::milliseconds>(due_at - Steady::now()),
                     std::chrono::milliseconds(0), kLongestWait);
      size_t count = 0;
      try {
        count = pty_->read(buffer, sizeof buffer, wait);
      } catch (const serial::SerialError& e) {
        log().error("{}; the simulated adaptor stops", e.what());
        return;
      }
      if (count > 0) answer_host(std::string_view(buffer, count));
      const auto due = schedule.due(scene_time(), next);
      if (!due) continue;
      // A real adaptor keeps what the bus carried while its USB link stalled and sends it
      // late; with timestamps ("Z1") the frames still carry the bus's times, so the samples of
      // the last kCatchUp_s are all sent. Without, a late sample would look taken when read:
      // those in between are skipped.
      uint64_t first = due->index;
      if (adaptor_.timestamps()) {
        first -= std::min(due->skipped, static_cast<uint64_t>(kCatchUp_s * settings_.rate_hz));
      }
      skipped_ += first - next;
      for (uint64_t index = first; index <= due->index; ++index) {
        send_sample(schedule.time_of(index));
      }
      next = due->index + 1;
    }
  }

  void answer_host(std::string_view bytes) {
    const bool was_open = adaptor_.is_open();
    const uint64_t refused = adaptor_.stats().refused;
    const std::string answers = adaptor_.feed(bytes);
    if (adaptor_.stats().refused != refused) {
      log().warn("refused a host command: {}", adaptor_.last_refusal());
    }
    if (adaptor_.is_open() != was_open) {
      if (adaptor_.is_open()) {
        log().info("host opened the channel at {} bit/s", *adaptor_.bitrate());
        if (*adaptor_.bitrate() != settings_.bitrate) {
          log().warn("the box sends at {} bit/s: the host at {} bit/s receives nothing",
                     settings_.bitrate, *adaptor_.bitrate());
        }
      } else {
        log().info("host closed the channel");
      }
    }
    if (answers.empty()) return;
    try {
      pty_->write_all(answers);
    } catch (const serial::SerialError& e) {
      log().warn("cannot answer the host: {}", e.what());
    }
  }

  void send_sample(double time_s) {
    if (!adaptor_.is_open() || adaptor_.bitrate() != settings_.bitrate || !pty_->peer_connected()) {
      ++held_back_;
      return;
    }
    const int64_t stamp_ns =
        adaptor_.timestamps() ? scene_start_wall_ns_ + std::llround(time_s * 1e9) : wall_clock_ns();
    std::string bytes;
    for (const can::CanFrame& frame : simulator_->frames_at(time_s, stamp_ns)) {
      bytes += adaptor_.frame_message(frame, stamp_ns);
    }
    try {
      pty_->write_all(bytes);
      ++sent_;
      writing_fails_ = false;
    } catch (const serial::SerialError& e) {
      ++failed_writes_;
      if (!writing_fails_) log().warn("dropping samples: {}", e.what());
      writing_fails_ = true;
    }
  }

  void publish_truth() {
    auto message = std::make_shared<mocap_msgs::msg::RobotPoseArray>();
    message->header().stamp(to_time_msg(now()));
    message->header().frame_id(kTruthFrame);
    for (const RobotTruth& truth : simulator_->ground_truth(scene_time())) {
      mocap_msgs::msg::RobotPose pose;
      pose.name(truth.name);
      pose.x(truth.pose.x);
      pose.y(truth.pose.y);
      pose.theta(truth.pose.theta);
      message->robots().push_back(std::move(pose));
    }
    truths_.publish(std::move(message));
  }

  std::unique_ptr<PixartBoxSimulator> simulator_;
  Steady::time_point scene_start_;
  int64_t scene_start_wall_ns_ = 0;  // scene_start_ on the wall clock, for frame timestamps
  Publisher<mocap_msgs::msg::RobotPoseArray> truths_;
  // pty output; the adaptor and the counters belong to the worker thread until it ends.
  std::optional<serial::PseudoTerminal> pty_;
  std::optional<serial::DeviceLink> device_link_;
  SimulatedSlcanAdaptor adaptor_;
  uint64_t sent_ = 0, skipped_ = 0, held_back_ = 0, failed_writes_ = 0;
  bool writing_fails_ = false;
  // candump output
  std::ofstream log_stream_;
  std::ofstream truth_stream_;
};

}  // namespace
}  // namespace mocap::pixart

MOCAP_REGISTER_COMPONENT(mocap::pixart::PixartBoxSim, "pixart_box_sim")
