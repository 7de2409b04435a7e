// Finds bright round fiducials in mono8 infrared images: seed 000 §5.7 (threshold at a ratio
// of the brightest pixel, connected regions, centroid, area and circularity filters), made
// sub-pixel and fast enough for thousands of 1280x720 frames per second on one core.
//
// How it stays fast: one SIMD pass computes the brightest pixel of every row; only rows that
// reach the threshold are read again, in SIMD chunks that skip dark stretches, and their
// bright pixels are grouped into runs. Runs that touch runs of the row above are joined
// (union-find), so connected regions come out of one top-to-bottom sweep with no binary image,
// no visited mask and no contour search over the frame. Each region's sums (pixels, intensity,
// moments) are kept per run as the runs are found, while the pixels are in cache. Only the
// outline (for circularity) and the centroid look at a region's neighbourhood, on a small
// patch around it.
// A FiducialDetector keeps every buffer between frames, so a frame allocates nothing once the
// buffers have grown to the scene.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace mocap::tracking {

struct FiducialDetectorOptions {
  // Pixels brighter than threshold_ratio x the brightest pixel (in the region of interest)
  // belong to fiducials. The seed used 0.75 with large, saturated markers. A marker only 3-4
  // px across (15 mm at 3.5 m) peaks anywhere from ~60 % to 100 % of a saturated one,
  // depending on where its centre falls on the pixel grid, so at 0.75 distant markers drop
  // out at random (tracking_accuracy_bench: 95-98.6 % tracked at 0.75, 100 % at 0.5); lower
  // still lets glows and reflections in.
  double threshold_ratio = 0.5;
  // Floor of the threshold, grey levels. In a frame without markers the brightest pixel is
  // noise, and a ratio of it would turn noise into detections; with the floor such a frame
  // yields nothing.
  double min_threshold = 40;
  // Regions of fewer pixels are noise: hot pixels, sparkle.
  int min_area_px = 3;
  // Regions of more pixels are lamps, windows or reflections, not markers.
  int max_area_px = 2000;
  // Regions less round than this are rejected: circularity 4πA/P² (DetectedFiducial) is
  // 0.95-1 for an imaged disc of radius 2 px or more, about 0.5 for a 1:4 ellipse (edges,
  // cables, glints). 0.6 keeps markers seen up to about 70° off face-on.
  double min_circularity = 0.6;
  // Circularity is judged only for regions of at least this many pixels. The outline of a
  // region of a few pixels follows a handful of noisy pixel values, not the shape of the
  // marker, and a distant marker would be rejected at random. Smaller regions report their
  // circularity but are not filtered by it.
  int circularity_min_area_px = 12;
  // Where to look, in image pixels; an empty rectangle means the whole image. Clipped to the
  // image. Reported coordinates are always in the full image.
  cv::Rect region_of_interest;
  // 8: pixels touching diagonally belong to one region (a marker's rim often touches only
  // diagonally); 4: only pixels sharing an edge.
  int connectivity = 8;
  // The centroid is taken over a window around the region, this many pixels wider on each
  // side than the region's bounding box, so that it sees the blob's flanks below the
  // threshold (see DetectedFiducial::x). 0: only the region's own pixels, weighted by how far
  // they exceed the threshold, as the seed's threshold-only view would give.
  int centroid_margin_px = 3;
  // Where the centroid's weights start, as a fraction of the way from the local background
  // (median of the window's rim) up to the threshold: low enough that the weights follow most
  // of the blob's profile, high enough that background noise carries no weight.
  double centroid_level = 0.25;
  // 1-sigma noise of one pixel value, grey levels (read noise and quantisation of the camera).
  // Sets uncertainty_px; it does not change detection.
  double pixel_noise = 2.0;
  // The error a centroid of sampled pixels keeps however low the noise, as a one-pixel blob
  // would have it: a blob of A pixels keeps sampling_error_px / sqrt(A), added to the noise's
  // in quadrature (DetectedFiducial::uncertainty_px). Measured on the volume demo's rendered
  // images, whose lone markers' windowed centroids erred by 0.037 px RMS at 3 pixels above
  // the threshold, 0.018 at 10 and 0.013 at 25: 0.06 / sqrt(A) throughout, 3 x that for a
  // threshold-only centroid. Weighing fiducials by it rather than alike sharpens a pose fused
  // from several cameras.
  double sampling_error_px = 0.06;
  // Regions touching the edge of the image (or of the region of interest) are cut off and
  // their centroid pulled inward. false: keep them, flagged touches_border; true: reject.
  bool reject_border_regions = false;

  // Why these options cannot be used, naming the field ("connectivity: 5; 4 or 8");
  // nullopt when they can. FiducialDetector's constructor throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

struct DetectedFiducial {
  // Background-subtracted intensity-weighted centroid, pixels; x right, y down. The centre of
  // the top-left pixel is (0, 0) (OpenCV's and ROS's camera model convention). Weights are
  // wᵢ = Iᵢ - level over the pixels of the window (centroid_margin_px) brighter than
  // level = background + centroid_level x (threshold - background). Weighting only the pixels
  // above the threshold, as the seed did, sees a few pixels of a small blob's top and locks
  // to the pixel grid (errors up to 0.1 px on blurred discs); the lower level sees the flanks
  // too and brings that to a few hundredths. A weight that falls to zero at the level also
  // keeps the centroid smooth as a blob slides across the grid. A region with another region
  // near enough to share its window falls back to weights Iᵢ - threshold over its own pixels.
  double x = 0;
  double y = 0;
  double area_px = 0;  // pixels above the threshold
  // 4πA/P² of the sub-pixel outline where the image crosses the threshold (marching squares,
  // fiducial_tracker.cpp): 1 for a perfect disc, 0.95-1 for imaged ones of radius 2 px or
  // more, π/4 for a lone pixel, lower the longer and rougher a blob is.
  double circularity = 0;
  double peak = 0;  // brightest pixel, grey levels
  // 1-sigma position error per axis, pixels. The centroid x̂ = Σ wᵢxᵢ / W (W = Σ wᵢ) moves by
  // (xᵢ - x̂)/W per grey level of pixel i, so independent pixel noise σ gives
  //   var(x̂) = σ² Σ (xᵢ - x̂)² / W²   (likewise y),
  // and uncertainty_px = sqrt((var(x̂) + var(ŷ)) / 2 + s² / area_px), where s is
  // sampling_error_px (3 x that for a threshold-only centroid). Bright, large blobs are
  // precise; faint or small ones are not. Ignores the threshold's own noise.
  double uncertainty_px = 0;
  bool touches_border = false;  // part of the region lies on the image or ROI edge
};

// What one detection did, for logs and tuning.
struct DetectionStats {
  int peak = 0;            // brightest pixel of the region of interest
  double threshold = 0;    // pixels brighter than this were used
  int regions = 0;         // connected bright regions found
  int rejected_small = 0;  // fewer than min_area_px pixels
  int rejected_large = 0;  // more than max_area_px pixels
  int rejected_at_border = 0;
  int rejected_not_round = 0;  // circularity below min_circularity
  int accepted = 0;
};

// A detector that keeps its buffers from frame to frame: use one per image stream.
class FiducialDetector {
 public:
  // Throws std::invalid_argument for options out of range.
  explicit FiducialDetector(FiducialDetectorOptions options = {});

  // The fiducials of `mono8` (CV_8UC1, any step; empty gives none), in the order of their
  // topmost pixel (row by row). Valid until the next call. Throws std::invalid_argument for
  // another pixel type.
  const std::vector<DetectedFiducial>& detect(const cv::Mat& mono8,
                                              DetectionStats* stats = nullptr);

  const FiducialDetectorOptions& options() const { return options_; }
  // Throws std::invalid_argument for options out of range.
  void set_options(const FiducialDetectorOptions& options);

 private:
  // Bright pixels [x_begin, x_end) of one row of the region of interest, with their sums.
  struct Run {
    int y = 0;
    int x_begin = 0;
    int x_end = 0;
    int parent = 0;               // union-find; a region's root is its first run
    int next_in_region = -1;      // runs of one region, in scan order
    int region = -1;              // index into regions_, set for roots
    int64_t sum_intensity = 0;    // Σ I
    int64_t sum_intensity_x = 0;  // Σ I·x
    int peak = 0;
  };
  struct Region {
    int first_run = 0;
    int last_run = 0;
    int64_t pixels = 0;
    int64_t sum_intensity = 0, sum_intensity_x = 0, sum_intensity_y = 0;
    int64_t sum_x = 0, sum_xx = 0, sum_y = 0, sum_yy = 0;
    int peak = 0;
    int x_min = 0, x_max = 0, y_min = 0, y_max = 0;  // inclusive bounding box
    bool crowded = false;  // another region is within reach of its centroid window
  };

  // Position and 1-sigma error (per axis, before the floor) of a centroid.
  struct Centroid {
    double x = 0, y = 0, sigma = 0;
  };

  void find_runs(const cv::Mat& roi, int level);
  void join_runs(int previous_begin, int previous_end, int current_begin);
  int find_root(int run);
  void collect_regions();
  void mark_crowded_regions();
  double circularity(const cv::Mat& roi, const Region& region, double threshold);
  // patch_values_ for `region`'s bounding box and a margin of one pixel (circularity says how).
  void fill_outline_patch(const cv::Mat& roi, const Region& region, double threshold);
  Centroid region_centroid(const Region& region, double threshold) const;
  // A centroid window: a rectangle of the region of interest (inclusive), cut to a disc when
  // radius is finite.
  struct Window {
    int left = 0, right = 0, top = 0, bottom = 0;
    double centre_x = 0, centre_y = 0;
    double radius = std::numeric_limits<double>::infinity();
  };
  bool window_centroid(const cv::Mat& roi, int index, double threshold, Centroid& out);
  bool weighted_centroid(const cv::Mat& roi, const Window& window, double threshold, Centroid& out);

  FiducialDetectorOptions options_;
  std::vector<uint8_t> row_peaks_;
  std::vector<Run> runs_;
  std::vector<Region> regions_;
  std::vector<uint8_t> patch_mask_;            // one region's pixels, around its bounding box
  std::vector<float> patch_values_;            // and their values relative to the threshold
  std::vector<std::pair<int, int>> crowding_;  // regions within reach of each other, both ways
  std::vector<uint8_t> window_rim_;            // a centroid window's rim, for its median
  std::vector<DetectedFiducial> fiducials_;
};

// One-off detection; a FiducialDetector is faster for a stream (it keeps its buffers).
std::vector<DetectedFiducial> detect_fiducials(const cv::Mat& mono8,
                                               const FiducialDetectorOptions& options = {},
                                               DetectionStats* stats = nullptr);

}  // namespace mocap::tracking
