// volume_calibration_solve: a volume's calibration solved from its recorded sessions, for the
// page to watch (calibration_session.hpp: what mocap_volume_calibrate runs and prints). On a
// worker of its own: the waved session's coverage on /calibration/coverage, the solve's progress
// on /calibration/progress (and a bar in the log), then the report on /calibration/result and in
// the log, line by line as the tool prints it; the camera files written into `output`. Then it
// ends the process (0 calibrated, 1 it could not be, 2 its input could not be read), unless
// `exit_when_done` is false: then it keeps the report for the page until stopped.
#include <chrono>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <mocap/component.hpp>
#include <mocap/config_files.hpp>
#include <mocap_msgs/msg/calibration_coverage.hpp>
#include <mocap_msgs/msg/calibration_progress.hpp>
#include <mocap_msgs/msg/volume_calibration_result.hpp>

#include "common/topics/graph_topics.hpp"
#include "volume/volume_calibration/calibration_messages.hpp"
#include "volume/volume_calibration/calibration_session.hpp"

namespace mocap::volume {
namespace {

using CoverageMessage = mocap_msgs::msg::CalibrationCoverage;
using ProgressMessage = mocap_msgs::msg::CalibrationProgress;
using ResultMessage = mocap_msgs::msg::VolumeCalibrationResult;

struct Settings {
  std::string waved;
  std::vector<std::string> floor;
  std::string output;
  std::vector<std::string> cameras = {mocap::config_file("volume/cameras/cam_0.yaml"),
                                      mocap::config_file("volume/cameras/cam_1.yaml"),
                                      mocap::config_file("volume/cameras/cam_2.yaml"),
                                      mocap::config_file("volume/cameras/cam_3.yaml")};
  std::string board = "board_a";
  std::string database = mocap::config_file("constellations.yaml");
  bool exit_when_done = true;
  double progress_period_s = 0.25;
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("waved", "the bag of the board waved through the volume", &Settings::waved)
        .path()
        .add("floor",
             "the bags of the board on the floor, each BAG:X,Y (its centre at the mark X, Y in "
             "metres; BAG alone: 0,0): one, or three or more marks not in a line",
             &Settings::floor)
        .add("output", "the folder the calibrated camera files are written into", &Settings::output)
        .path()
        .add("cameras", "the volume's camera files: intrinsics, names, the poses they had",
             &Settings::cameras)
        .path()
        .add("board", "the board waved and laid on the floor, in the database", &Settings::board)
        .add("database", "the board's constellation database", &Settings::database)
        .path()
        .add("exit_when_done",
             "end the process once the report is out (false: keep it for the page until stopped)",
             &Settings::exit_when_done)
        .add("progress_period_s", "the shortest time between two progress messages and log lines",
             &Settings::progress_period_s)
        .range(0.0, 60.0);

class CalibrationSolveComponent final : public Component {
  // Before the other members, which start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "A volume's cameras calibrated from the recorded waved and floor sessions (what "
        "mocap_volume_calibrate does), its progress and report published for the page and "
        "logged; the calibrated camera files written into `output`.");
    kParameters.declare(spec);
    spec.publishes<CoverageMessage>(topics::kCalibrationCoverage, Qos::latched(),
                                    "the waved session's coverage, once read");
    spec.publishes<ProgressMessage>(topics::kCalibrationProgress, Qos::latched(),
                                    "the solve's stage and share done, as it goes");
    spec.publishes<ResultMessage>(topics::kCalibrationResult, Qos::latched(),
                                  "the report, once calibrated");
  }

  explicit CalibrationSolveComponent(Context& context) : Component(context) {
    session_.waved = settings_.waved;
    session_.output = settings_.output;
    session_.camera_files = settings_.cameras;
    session_.board = settings_.board;
    session_.database = settings_.database;
    if (session_.waved.empty())
      throw std::invalid_argument("waved: the waved session's bag is needed");
    if (session_.output.empty()) throw std::invalid_argument("output: a folder is needed");
    if (settings_.floor.empty()) {
      throw std::invalid_argument("floor: one bag of the board on the floor or more is needed");
    }
    for (const std::string& floor : settings_.floor) {
      auto recording = parse_floor_recording(floor);
      if (!recording) {
        throw std::invalid_argument(
            fmt::format("floor: {}: the mark after ':' is not X,Y in metres", floor));
      }
      session_.floor.push_back(*recording);
    }
    coverage_ = create_publisher<CoverageMessage>(topics::kCalibrationCoverage);
    progress_ = create_publisher<ProgressMessage>(topics::kCalibrationProgress);
    result_ = create_publisher<ResultMessage>(topics::kCalibrationResult);
    create_worker("solve", [this](std::stop_token stop) { solve(stop); });
  }

 private:
  void solve(std::stop_token stop) {
    int exit_code = 0;
    try {
      const CalibrationSessionResult result = run_calibration_session(
          session_, [this](const SessionProgress& progress) { report(progress); }, stop);
      coverage_.publish(
          coverage_message(result.coverage, CoverageOptions{}, result.coverage_stamp_ns));
      for (const std::string& line : problem_lines(result)) log().warn("{}", line);
      for (const std::string& line : report_lines(result)) log().info("report: {}", line);
      // Said done in the log before the page can have the result: a script that follows the log
      // has the whole report by the time a page's watcher is through.
      report({"done", 1, fmt::format("the camera files are in {}", settings_.output)}, true);
      result_.publish(result_message(result));
    } catch (const VolumeCalibrationError& e) {
      if (stop.stop_requested()) return;
      log().error("cannot calibrate the volume: {}", e.what());
      report({"failed", 0, e.what()}, true);
      exit_code = 1;
    } catch (const CalibrationSessionError& e) {
      log().error("{}", e.what());
      report({"failed", 0, e.what()}, true);
      exit_code = 2;
    }
    if (settings_.exit_when_done || exit_code != 0) request_shutdown(exit_code);
  }

  // Published and logged at most every progress period, and at each new stage.
  void report(const SessionProgress& progress, bool always = false) {
    const auto now = std::chrono::steady_clock::now();
    if (!always && progress.stage == stage_ &&
        now - reported_ < std::chrono::duration<double>(settings_.progress_period_s)) {
      return;
    }
    stage_ = progress.stage;
    reported_ = now;
    progress_.publish(progress_message(progress));
    log().info("{}", progress_line(progress));
  }

  CalibrationSession session_;
  Publisher<CoverageMessage> coverage_;
  Publisher<ProgressMessage> progress_;
  Publisher<ResultMessage> result_;
  std::string stage_;
  std::chrono::steady_clock::time_point reported_{};
};

}  // namespace
}  // namespace mocap::volume

MOCAP_REGISTER_COMPONENT(mocap::volume::CalibrationSolveComponent, "volume_calibration_solve")
