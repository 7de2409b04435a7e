// constellation_identifier: FiducialArray -> ConstellationArray (constellation_identifier.hpp).
#include <chrono>
#include <limits>
#include <memory>
#include <optional>

#include <mocap/calibration/camera_file.hpp>
#include <mocap/component.hpp>
#include <mocap/config_files.hpp>
#include <mocap_msgs/msg/constellation_array.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>

#include "common/topics/graph_topics.hpp"
#include "tracking/constellation_database/database_parameters.hpp"
#include "tracking/constellation_identifier/constellation_identifier.hpp"
#include "tracking/constellation_identifier/constellation_message.hpp"

namespace mocap::constellations {
namespace {

// The identifier's options with the files only the plugin reads.
struct Settings : IdentifierOptions {
  DatabaseFiles boards;
  std::string camera;  // empty: fiducials taken as they are, distortion and all
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .include(&Settings::boards, database_parameters())
        .add("camera", "camera file; when given, lens distortion is removed before the line search",
             &Settings::camera)
        .path()
        .add("cross_ratio_tolerance",
             "largest relative cross-ratio difference (the seed used 0.20)",
             &Settings::cross_ratio_tolerance)
        .range(1e-4, 0.5)
        .add("line_tolerance_px", "largest distance of a point from its line, pixels",
             &Settings::line_search, &LineSearchOptions::tolerance_px)
        .range(0.01, 100)
        .add("min_lines", "fewest lines that identify a constellation", &Settings::min_lines)
        .range(1, 64)
        .add("min_extra_markers",
             "with two whole lines only, markers that must lie where their plane puts them (a "
             "board with a hidden corner); 0 = never identify from two lines",
             &Settings::min_extra_markers)
        .range(0, 1000)
        .add("max_fit_error_px",
             "largest distance of a point from the constellation's plane fit, pixels",
             &Settings::max_fit_error_px)
        .range(0.01, 1000);

class ConstellationIdentifierComponent final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Finds collinear fiducials, names lines by their cross-ratio and constellations by "
        "their lines; publishes each constellation's image points in database order.");
    kParameters.declare(spec);
    spec.subscribes<mocap_msgs::msg::FiducialArray>(topics::kFiducials, Qos::reliable(),
                                                    "fiducials of one image, pixels");
    spec.publishes<mocap_msgs::msg::ConstellationArray>(
        topics::kConstellations, Qos::reliable(),
        "constellations identified in each fiducial array: each line's fiducials in database "
        "order, NaN for a marker not seen");
  }

  explicit ConstellationIdentifierComponent(Context& context)
      : Component(context), database_(settings_.boards.load()) {
    if (!settings_.camera.empty()) camera_ = calibration::load_camera_file(settings_.camera).model;
    identifier_.emplace(database_, settings_);
    for (const std::string& problem : database_.ambiguities(settings_.cross_ratio_tolerance)) {
      log().warn("{}", problem);
    }
    log().info("{} constellations from {}", database_.constellations().size(),
               settings_.boards.database);
    publisher_ = create_publisher<mocap_msgs::msg::ConstellationArray>(topics::kConstellations);
    create_subscription<mocap_msgs::msg::FiducialArray>(
        topics::kFiducials,
        [this](const mocap_msgs::msg::FiducialArray& array) { identify(array); });
  }

  ~ConstellationIdentifierComponent() override {
    log().info("{} arrays, {} constellations identified, {} non-finite fiducials ignored", arrays_,
               identified_, non_finite_);
  }

 private:
  void identify(const mocap_msgs::msg::FiducialArray& array) {
    ++arrays_;
    const auto& fiducials = array.fiducials();
    points_.resize(fiducials.size());
    for (size_t i = 0; i < fiducials.size(); ++i) {
      Eigen::Vector2d pixel(fiducials[i].x(), fiducials[i].y());
      points_[i] = ideal_pixel(pixel);
      if (!points_[i].allFinite()) ++non_finite_;
    }
    auto message = std::make_shared<mocap_msgs::msg::ConstellationArray>();
    message->header(array.header());
    for (const IdentifiedConstellation& found : identifier_->identify(points_)) {
      message->constellations().push_back(to_constellation_message(found, array));
      ++identified_;
    }
    publisher_.publish(std::move(message));
  }

  // Lines are straight only without lens distortion: pixels through the camera model,
  // scaled back to pixel units so the tolerances keep their meaning.
  Eigen::Vector2d ideal_pixel(const Eigen::Vector2d& pixel) const {
    if (!camera_ || !pixel.allFinite()) return pixel;
    auto ray = camera_->unproject(pixel);
    if (!ray) return Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
    return camera_->focal_length_px() * ray->head<2>();
  }

  ConstellationDatabase database_;
  std::shared_ptr<const calibration::CameraModel> camera_;
  std::optional<ConstellationIdentifier> identifier_;
  Publisher<mocap_msgs::msg::ConstellationArray> publisher_;
  std::vector<Eigen::Vector2d> points_;
  uint64_t arrays_ = 0, identified_ = 0, non_finite_ = 0;
};

}  // namespace
}  // namespace mocap::constellations

MOCAP_REGISTER_COMPONENT(mocap::constellations::ConstellationIdentifierComponent,
                         "constellation_identifier")
