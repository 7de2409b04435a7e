// fiducial_tracker: finds fiducials in camera images (fiducial_detector.hpp) and publishes
// them, one FiducialArray per image, stamped and framed as the image was.
#include <chrono>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <vector>

#include <mocap/component.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>
#include <sensor_msgs/msg/image.hpp>

#include "fiducial_detector.hpp"
#include "image_message.hpp"

namespace mocap::tracking {
namespace {

constexpr const char* kImageTopic = "/camera/ir/image_raw";
constexpr const char* kFiducialTopic = "/mocap/fiducials";

class FiducialTracker final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    const FiducialDetectorOptions defaults;
    spec.description(
        "Finds bright round fiducials in mono8 camera images: threshold at a ratio of the "
        "brightest pixel, connected regions filtered by area and circularity, "
        "background-subtracted intensity-weighted sub-pixel centroids.");
    spec.parameter("threshold_ratio", defaults.threshold_ratio,
                   "pixels brighter than this fraction of the brightest pixel are fiducial")
        .range(0, 1);
    spec.parameter("min_threshold", defaults.min_threshold,
                   "floor of the threshold, grey levels: a dark frame yields nothing")
        .range(0, 255);
    spec.parameter("min_area_px", defaults.min_area_px, "smaller regions are noise").min(1);
    spec.parameter("max_area_px", defaults.max_area_px, "larger regions are lamps or reflections")
        .min(1);
    spec.parameter("min_circularity", defaults.min_circularity,
                   "4πA/P² below which a region is rejected (1 = disc)")
        .range(0, 1);
    spec.parameter("circularity_min_area_px", defaults.circularity_min_area_px,
                   "circularity is judged only for regions of at least this many pixels")
        .min(0);
    spec.parameter("roi", std::vector<int64_t>{},
                   "region of interest [x, y, width, height] in pixels; [] = whole image")
        .min(0);
    spec.parameter("connectivity", defaults.connectivity, "4 or 8 neighbours join a region")
        .range(4, 8);
    spec.parameter("centroid_margin_px", defaults.centroid_margin_px,
                   "the centroid window reaches this far beyond a region; 0 = only its pixels")
        .min(0);
    spec.parameter("centroid_level", defaults.centroid_level,
                   "centroid weights start this far from the local background to the threshold")
        .range(0, 1);
    spec.parameter("pixel_noise", defaults.pixel_noise,
                   "1-sigma noise of a pixel, grey levels; sets each fiducial's uncertainty")
        .min(0);
    spec.parameter("uncertainty_floor_px", defaults.uncertainty_floor_px,
                   "least uncertainty a fiducial reports, pixels")
        .min(0);
    spec.parameter("reject_border_regions", defaults.reject_border_regions,
                   "reject regions cut by the image or ROI edge (else kept)");
    spec.parameter("report_period_s", 5.0, "seconds between summary log lines").range(0.1, 86400);
    spec.subscribes<sensor_msgs::msg::Image>(kImageTopic, Qos::sensor_data(),
                                             "camera images, mono8");
    spec.publishes<mocap_msgs::msg::FiducialArray>(
        kFiducialTopic, Qos::reliable(),
        "one array per image, with the image's header; x, y = centroid (pixels, centre of "
        "the top-left pixel at 0, 0), z = 0 (unused for image points), size = area in pixels, "
        "uncertainty = 1-sigma position error in pixels");
  }

  explicit FiducialTracker(Context& context)
      : Component(context), detector_(options_from_parameters()) {
    publisher_ = create_publisher<mocap_msgs::msg::FiducialArray>(kFiducialTopic);
    create_subscription<sensor_msgs::msg::Image>(
        kImageTopic, [this](const sensor_msgs::msg::Image& image) { on_image(image); });
    report_period_s_ = param<double>("report_period_s");
    create_timer(std::chrono::duration_cast<std::chrono::nanoseconds>(
                     std::chrono::duration<double>(report_period_s_)),
                 [this] { report(); });
  }

  ~FiducialTracker() override {
    log().info("{} images in all, {:.1f} fiducials per image, {} dropped", images_total_,
               images_total_ > 0 ? static_cast<double>(fiducials_total_) / images_total_ : 0.0,
               drops_total_);
  }

 private:
  FiducialDetectorOptions options_from_parameters() const {
    FiducialDetectorOptions options;
    options.threshold_ratio = param<double>("threshold_ratio");
    options.min_threshold = param<double>("min_threshold");
    options.min_area_px = param<int>("min_area_px");
    options.max_area_px = param<int>("max_area_px");
    options.min_circularity = param<double>("min_circularity");
    options.circularity_min_area_px = param<int>("circularity_min_area_px");
    options.connectivity = param<int>("connectivity");
    options.centroid_margin_px = param<int>("centroid_margin_px");
    options.centroid_level = param<double>("centroid_level");
    options.pixel_noise = param<double>("pixel_noise");
    options.uncertainty_floor_px = param<double>("uncertainty_floor_px");
    options.reject_border_regions = param<bool>("reject_border_regions");
    const auto roi = param<std::vector<int>>("roi");
    if (!roi.empty()) {
      if (roi.size() != 4 || roi[2] == 0 || roi[3] == 0) {
        throw std::invalid_argument(
            "roi must be [] or [x, y, width, height] with a positive width and height");
      }
      options.region_of_interest = cv::Rect(roi[0], roi[1], roi[2], roi[3]);
    }
    // The launcher checked each value's range; the detector's constructor checks the
    // combinations (max_area_px below min_area_px, connectivity 5).
    return options;
  }

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
                   kImageTopic, drops_total_, view.problem);
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
    ++images_total_;
    ++images_since_report_;
    fiducials_total_ += detected.size();
    fiducials_since_report_ += detected.size();
  }

  void report() {
    if (images_since_report_ == 0 && drops_since_report_ == 0) {
      // Said once, not every period, until images come again.
      if (!reported_silence_) {
        log().info("no images on {} in the last {} s", kImageTopic, report_period_s_);
      }
      reported_silence_ = true;
      return;
    }
    reported_silence_ = false;
    log().info("{} images in {} s, {:.1f} fiducials per image, {} dropped ({} in all)",
               images_since_report_, report_period_s_,
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
  double report_period_s_ = 5;
  uint64_t images_total_ = 0, images_since_report_ = 0;
  uint64_t fiducials_total_ = 0, fiducials_since_report_ = 0;
  uint64_t drops_total_ = 0, drops_since_report_ = 0, drops_unlogged_ = 0;
  std::chrono::steady_clock::time_point last_drop_log_;
  bool reported_silence_ = false;
};

}  // namespace
}  // namespace mocap::tracking

MOCAP_REGISTER_COMPONENT(mocap::tracking::FiducialTracker, "fiducial_tracker")
