// fiducial_tracker: finds fiducials in camera images (fiducial_tracker.hpp) and publishes
// them, one FiducialArray per image, stamped and framed as the image was.
#include <chrono>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <vector>

#include <mocap/component.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>
#include <sensor_msgs/msg/image.hpp>

#include "common/image_message/image_message.hpp"
#include "common/topics/graph_topics.hpp"
#include "tracking/fiducial_tracker/fiducial_tracker.hpp"

namespace mocap::tracking {
namespace {

// The detector's options with what only the plugin reads.
struct Settings : FiducialDetectorOptions {
  std::vector<int> roi;  // [x, y, width, height], or empty: region_of_interest
  double report_period_s = 5;
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("threshold_ratio",
             "pixels brighter than this fraction of the brightest pixel are fiducial",
             &Settings::threshold_ratio)
        .range(0, 1)
        .add("min_threshold", "floor of the threshold, grey levels: a dark frame yields nothing",
             &Settings::min_threshold)
        .range(0, 255)
        .add("min_area_px", "smaller regions are noise", &Settings::min_area_px)
        .min(1)
        .add("max_area_px", "larger regions are lamps or reflections", &Settings::max_area_px)
        .min(1)
        .add("min_circularity", "4πA/P² below which a region is rejected (1 = disc)",
             &Settings::min_circularity)
        .range(0, 1)
        .add("circularity_min_area_px",
             "circularity is judged only for regions of at least this many pixels",
             &Settings::circularity_min_area_px)
        .min(0)
        .add("roi", "region of interest [x, y, width, height] in pixels; [] = whole image",
             &Settings::roi)
        .min(0)
        .add("connectivity", "4 or 8 neighbours join a region", &Settings::connectivity)
        .range(4, 8)
        .add("centroid_margin_px",
             "the centroid window reaches this far beyond a region; 0 = only its pixels",
             &Settings::centroid_margin_px)
        .min(0)
        .add("centroid_level",
             "centroid weights start this far from the local background to the threshold",
             &Settings::centroid_level)
        .range(0, 1)
        .add("pixel_noise",
             "1-sigma noise of a pixel, grey levels; sets each fiducial's uncertainty",
             &Settings::pixel_noise)
        .min(0)
        .add("sampling_error_px",
             "centroid error of a one-pixel blob without noise; A pixels keep it / sqrt(A)",
             &Settings::sampling_error_px)
        .min(0)
        .add("reject_border_regions", "reject regions cut by the image or ROI edge (else kept)",
             &Settings::reject_border_regions)
        .add("report_period_s", "seconds between summary log lines", &Settings::report_period_s)
        .range(0.1, 86400);

// The launcher checked each value's range; the detector's constructor checks the combinations
// (max_area_px below min_area_px, connectivity 5).
FiducialDetectorOptions detector_options(Settings settings) {
  const std::vector<int>& roi = settings.roi;
  if (!roi.empty()) {
    if (roi.size() != 4 || roi[2] == 0 || roi[3] == 0) {
      throw std::invalid_argument(
          "roi must be [] or [x, y, width, height] with a positive width and height");
    }
    settings.region_of_interest = cv::Rect(roi[0], roi[1], roi[2], roi[3]);
  }
  return settings;
}

class FiducialTracker final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Finds bright round fiducials in mono8 camera images: threshold at a ratio of the "
        "brightest pixel, connected regions filtered by area and circularity, "
        "background-subtracted intensity-weighted sub-pixel centroids.");
    kParameters.declare(spec);
    spec.subscribes<sensor_msgs::msg::Image>(topics::kCameraImage, Qos::sensor_data(),
                                             "camera images, mono8");
    spec.publishes<mocap_msgs::msg::FiducialArray>(
        topics::kFiducials, Qos::reliable(),
        "one array per image, with the image's header; x, y = centroid (pixels, centre of "
        "the top-left pixel at 0, 0), z = 0 (unused for image points), size = area in pixels, "
        "uncertainty = 1-sigma position error in pixels");
  }

  explicit FiducialTracker(Context& context)
      : Component(context), detector_(detector_options(settings_)) {
    publisher_ = create_publisher<mocap_msgs::msg::FiducialArray>(topics::kFiducials);
    create_subscription<sensor_msgs::msg::Image>(
        topics::kCameraImage, [this](const sensor_msgs::msg::Image& image) { on_image(image); });
    create_timer(std::chrono::duration_cast<std::chrono::nanoseconds>(
                     std::chrono::duration<double>(settings_.report_period_s)),
                 [this] { report(); });
  }

  ~FiducialTracker() override {
    log().info("{} images in all, {:.1f} fiducials per image, {} dropped", images_total_,
               images_total_ > 0 ? static_cast<double>(fiducials_total_) / images_total_ : 0.0,
               drops_total_);
  }

  void report_health(HealthReport& report) override {
    latency_.report(report, "capture -> fiducials sent");
    report.add("unreadable images", std::to_string(drops_total_));
    if (drops_total_ > reported_drops_) {
      report.flag(HealthLevel::warn,
                  fmt::format("{} unreadable image(s) since the last status: see the log",
                              drops_total_ - reported_drops_));
    }
    reported_drops_ = drops_total_;
  }

 private:
  void on_image(const sensor_msgs::msg::Image& image) {
    Mono8View view = view_mono8(image);
    if (!view.problem.empty()) {
      ++drops_total_;
      ++drops_since_report_;
      ++drops_unlogged_;
      auto now = std::chrono::steady_clock::now();
      // The first drop at once, then at most one line per second with the count.
      if (drops_total_ == 1 || now - last_drop_log_ >= std::chrono::seconds(1)) {
        log().warn("dropped {} unreadable image(s) on {} ({} in all): {}", drops_unlogged_,
                   topics::kCameraImage, drops_total_, view.problem);
        drops_unlogged_ = 0;
        last_drop_log_ = now;
      }
      return;
    }
    const std::vector<DetectedFiducial>& detected = detector_.detect(view.pixels);

    auto array = std::make_shared<mocap_msgs::msg::FiducialArray>();
    array->header(image.header());
    array->fiducials().reserve(detected.size());
    for (const DetectedFiducial& found : detected) {
      mocap_msgs::msg::Fiducial& fiducial = array->fiducials().emplace_back();
      fiducial.x(static_cast<float>(found.x));
      fiducial.y(static_cast<float>(found.y));
      fiducial.z(0.0f);  // image points have no depth
      fiducial.size(static_cast<float>(found.area_px));
      fiducial.uncertainty(static_cast<float>(found.uncertainty_px));
    }
    publisher_.publish(std::move(array));
    latency_.add(now() - from_time_msg(image.header().stamp()));
    ++images_total_;
    ++images_since_report_;
    fiducials_total_ += detected.size();
    fiducials_since_report_ += detected.size();
  }

  void report() {
    if (images_since_report_ == 0 && drops_since_report_ == 0) {
      // Said once, not every period, until images come again.
      if (!reported_silence_) {
        log().info("no images on {} in the last {} s", topics::kCameraImage,
                   settings_.report_period_s);
      }
      reported_silence_ = true;
      return;
    }
    reported_silence_ = false;
    log().info("{} images in {} s, {:.1f} fiducials per image, {} dropped ({} in all)",
               images_since_report_, settings_.report_period_s,
               images_since_report_ > 0
                   ? static_cast<double>(fiducials_since_report_) / images_since_report_
                   : 0.0,
               drops_since_report_, drops_total_);
    images_since_report_ = 0;
    fiducials_since_report_ = 0;
    drops_since_report_ = 0;
  }

  FiducialDetector detector_;
  Publisher<mocap_msgs::msg::FiducialArray> publisher_;
  uint64_t images_total_ = 0, images_since_report_ = 0;
  uint64_t fiducials_total_ = 0, fiducials_since_report_ = 0;
  uint64_t drops_total_ = 0, drops_since_report_ = 0, drops_unlogged_ = 0;
  uint64_t reported_drops_ = 0;  // drops_total_ at the last status
  LatencyFigures latency_;
  std::chrono::steady_clock::time_point last_drop_log_;
  bool reported_silence_ = false;
};

}  // namespace
}  // namespace mocap::tracking

MOCAP_REGISTER_COMPONENT(mocap::tracking::FiducialTracker, "fiducial_tracker")
