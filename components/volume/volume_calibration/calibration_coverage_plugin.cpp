// volume_calibration_coverage: a calibration session's coverage, live (calibration_coverage.hpp).
// Each camera's identified boards (/volume/<camera>/constellations, the topics the session
// records) fill its image's regions; /calibration/coverage carries every camera's for the page,
// and the log shows each camera's bar with what is still missing, as the command line shows the
// session's progress.
#include <chrono>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <mocap/calibration/camera_file.hpp>
#include <mocap/component.hpp>
#include <mocap/config_files.hpp>
#include <mocap_msgs/msg/calibration_coverage.hpp>
#include <mocap_msgs/msg/constellation_array.hpp>

#include "common/topics/graph_topics.hpp"
#include "tracking/constellation_database/database_parameters.hpp"
#include "volume/volume_calibration/calibration_coverage.hpp"
#include "volume/volume_calibration/calibration_messages.hpp"

namespace mocap::volume {
namespace {

using CoverageMessage = mocap_msgs::msg::CalibrationCoverage;
using mocap_msgs::msg::ConstellationArray;

struct Settings : CoverageOptions {
  std::vector<std::string> cameras = {mocap::config_file("volume/cameras/cam_0.yaml"),
                                      mocap::config_file("volume/cameras/cam_1.yaml"),
                                      mocap::config_file("volume/cameras/cam_2.yaml"),
                                      mocap::config_file("volume/cameras/cam_3.yaml")};
  constellations::DatabaseFiles boards;
  std::string board = "board_a";
  double report_period_s = 2;
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("cameras", "the session's camera files: their names and image sizes",
             &Settings::cameras)
        .path()
        .include(&Settings::boards, constellations::database_parameters())
        .add("board", "the board waved through the volume, in the database", &Settings::board)
        .add("views_per_region", "sightings each of an image's nine regions needs",
             &Settings::views_per_region)
        .range(1, 100000)
        .add("shared_shots",
             "capture times a camera needs with the board whole in it and in another camera",
             &Settings::shared_shots)
        .range(0, 1000000)
        .add("same_capture_s", "sightings this close in time are one capture time",
             &Settings::same_capture_s)
        .range(0.0, 1.0)
        .add("report_period_s", "how often the coverage is published and logged",
             &Settings::report_period_s)
        .range(0.05, 3600.0);

class CalibrationCoverageComponent final : public Component {
  // Before the other members, which start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "A volume calibration session's coverage as the board is waved: each camera's image "
        "regions the board has filled and the shots it shares with another camera, published "
        "for the page and logged as a progress bar with what is missing.");
    kParameters.declare(spec);
    spec.subscribes<ConstellationArray>(topics::kVolumeConstellations, Qos::reliable(),
                                        "one topic per camera: the boards it identified");
    spec.publishes<CoverageMessage>(topics::kCalibrationCoverage, Qos::latched(),
                                    "every camera's coverage, each report period");
  }

  explicit CalibrationCoverageComponent(Context& context)
      : Component(context), database_(settings_.boards.load()) {
    board_ = database_.find(settings_.board);
    if (board_ == nullptr) {
      throw std::invalid_argument(
          fmt::format("board: no '{}' in {}", settings_.board, settings_.boards.database));
    }
    std::vector<CoverageCamera> cameras;
    for (const std::string& file : settings_.cameras) {
      const calibration::CameraFile camera = calibration::load_camera_file(file);
      cameras.push_back({camera.name, {camera.model->width(), camera.model->height()}});
    }
    coverage_.emplace(cameras, settings_);
    publisher_ = create_publisher<CoverageMessage>(topics::kCalibrationCoverage);
    for (size_t c = 0; c < cameras.size(); ++c) {
      create_subscription<ConstellationArray>(
          topics::member_of(topics::kVolumeConstellations, cameras[c].name),
          [this, c](const ConstellationArray& array) {
            if (auto sighting = board_sighting(array, c, *board_)) {
              coverage_->add(*sighting);
              ++sightings_;
            }
          });
    }
    create_timer(std::chrono::duration_cast<std::chrono::nanoseconds>(
                     std::chrono::duration<double>(settings_.report_period_s)),
                 [this] { report(); });
    log().info("coverage of {} cameras by {}: {} sightings a region, {} shots shared",
               cameras.size(), settings_.board, settings_.views_per_region, settings_.shared_shots);
  }

  ~CalibrationCoverageComponent() override {
    log_coverage();  // the whole session's, the last lines a reader of the log takes
    log().info("{} sightings; the session {} complete", sightings_,
               coverage_->progress() >= 1 ? "is" : "is not");
  }

  void report_health(HealthReport& report) override {
    report.add("progress %", fmt::format("{:.0f}", 100 * coverage_->progress()));
    for (const CameraCoverage& camera : coverage_->cameras()) {
      if (!camera.missing.empty()) {
        report.flag(HealthLevel::warn,
                    fmt::format("{}: {}", camera.name, fmt::join(camera.missing, ", ")));
      }
    }
  }

 private:
  // Published each period; logged when it moved.
  void report() {
    publisher_.publish(
        coverage_message(coverage_->cameras(), settings_, coverage_->latest_stamp_ns()));
    if (sightings_ != logged_sightings_) log_coverage();
  }

  // A line a camera: "coverage cam_0 [=====     ]  50 %: missing lower left corner, ...".
  void log_coverage() {
    logged_sightings_ = sightings_;
    for (const CameraCoverage& camera : coverage_->cameras()) {
      log().info("coverage {}", coverage_line(camera));
    }
  }

  constellations::ConstellationDatabase database_;
  const constellations::ConstellationModel* board_ = nullptr;
  std::optional<CalibrationCoverage> coverage_;
  Publisher<CoverageMessage> publisher_;
  uint64_t sightings_ = 0, logged_sightings_ = 0;
};

}  // namespace
}  // namespace mocap::volume

MOCAP_REGISTER_COMPONENT(mocap::volume::CalibrationCoverageComponent, "volume_calibration_coverage")
