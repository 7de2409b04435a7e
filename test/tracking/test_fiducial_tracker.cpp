// The fiducial detector (components/tracking/fiducial_tracker): sub-pixel centroids of rendered
// blurred discs, the filters (threshold floor, area, circularity, border, region of
// interest), agreement with OpenCV's connected components and contours, the uncertainty
// estimate, Image messages that cannot be read, and the plugin in a launched graph.
#include <dlfcn.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <numbers>
#include <random>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <mocap/component_host.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/image_message/image_message.hpp"
#include "test/test_support.hpp"
#include "tracking/fiducial_tracker/fiducial_tracker.hpp"

namespace mocap::tracking {
namespace {

// --- Rendering ------------------------------------------------------------------------------

// A filled ellipse (a disc when the semi-axes are equal) centred at (cx, cy), pixel centres at
// integer coordinates, rotated by angle_rad.
struct Blob {
  double cx, cy;
  double semi_major, semi_minor;
  double brightness;
  double angle_rad = 0;
};
Blob disc(double cx, double cy, double radius, double brightness) {
  return {cx, cy, radius, radius, brightness};
}

struct Scene {
  int width = 200;
  int height = 150;
  double background = 10;
  double blur_sigma = 1.0;  // the optics; 0 = none
  double noise_sigma = 0;   // grey levels
  unsigned noise_seed = 1;
};

// Each pixel gets the blob's exact coverage (16 x 16 samples), then blur, noise and rounding
// to 8 bits, like a camera's image of a bright marker.
cv::Mat render(const Scene& scene, const std::vector<Blob>& blobs) {
  cv::Mat image(scene.height, scene.width, CV_32F, cv::Scalar(scene.background));
  constexpr int kSamples = 16;
  for (const Blob& blob : blobs) {
    const double c = std::cos(blob.angle_rad), s = std::sin(blob.angle_rad);
    const int reach = static_cast<int>(std::ceil(blob.semi_major)) + 1;
    for (int v = std::max(0, static_cast<int>(blob.cy) - reach);
         v <= std::min(scene.height - 1, static_cast<int>(blob.cy) + reach + 1); ++v) {
      for (int u = std::max(0, static_cast<int>(blob.cx) - reach);
           u <= std::min(scene.width - 1, static_cast<int>(blob.cx) + reach + 1); ++u) {
        int inside = 0;
        for (int i = 0; i < kSamples; ++i) {
          for (int j = 0; j < kSamples; ++j) {
            const double dx = u - 0.5 + (i + 0.5) / kSamples - blob.cx;
            const double dy = v - 0.5 + (j + 0.5) / kSamples - blob.cy;
            const double along = (c * dx + s * dy) / blob.semi_major;
            const double across = (-s * dx + c * dy) / blob.semi_minor;
            if (along * along + across * across <= 1) ++inside;
          }
        }
        image.at<float>(v, u) +=
            static_cast<float>(blob.brightness * inside / (kSamples * kSamples));
      }
    }
  }
  if (scene.blur_sigma > 0) cv::GaussianBlur(image, image, cv::Size(0, 0), scene.blur_sigma);
  if (scene.noise_sigma > 0) {
    std::mt19937 random(scene.noise_seed);
    std::normal_distribution<float> noise(0, static_cast<float>(scene.noise_sigma));
    for (auto it = image.begin<float>(); it != image.end<float>(); ++it) *it += noise(random);
  }
  cv::Mat mono8;
  image.convertTo(mono8, CV_8U);
  return mono8;
}

// --- Centroids ------------------------------------------------------------------------------

TEST(FiducialDetector, CentreOfTheTopLeftPixelIsTheOrigin) {
  cv::Mat image(40, 50, CV_8U, cv::Scalar(0));
  image(cv::Rect(9, 19, 3, 3)).setTo(200);  // pixels 9..11, 19..21: centred on (10, 20)
  image.at<uint8_t>(20, 10) = 250;
  FiducialDetectorOptions options;
  options.min_circularity = 0;
  auto found = detect_fiducials(image, options);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_DOUBLE_EQ(found[0].x, 10);
  EXPECT_DOUBLE_EQ(found[0].y, 20);
  EXPECT_EQ(found[0].peak, 250);
}

TEST(FiducialDetector, CentroidOfABlurredDiscIsWithinFiveHundredthsOfAPixel) {
  Scene scene;
  scene.noise_sigma = 2;
  std::mt19937 random(7);
  std::uniform_real_distribution<double> fraction(0, 1);
  FiducialDetector detector;
  double worst = 0;
  for (double radius : {2.5, 3.0, 4.5, 6.0}) {
    for (int trial = 0; trial < 25; ++trial) {
      // Sub-pixel offsets on a 5 x 5 grid, so every phase against the pixel grid is tried.
      const double cx = 100 + (trial % 5) / 5.0 + 0.1 * fraction(random);
      const double cy = 75 + (trial / 5) / 5.0 + 0.1 * fraction(random);
      scene.noise_seed = static_cast<unsigned>(trial + 1);
      cv::Mat image = render(scene, {disc(cx, cy, radius, 220)});
      const auto& found = detector.detect(image);
      ASSERT_EQ(found.size(), 1u) << "radius " << radius << " at " << cx << ", " << cy;
      EXPECT_NEAR(found[0].x, cx, 0.05) << "radius " << radius;
      EXPECT_NEAR(found[0].y, cy, 0.05) << "radius " << radius;
      worst = std::max({worst, std::abs(found[0].x - cx), std::abs(found[0].y - cy)});
    }
  }
  RecordProperty("worst_error_px", fmt::format("{:.4f}", worst));
}

TEST(FiducialDetector, ThresholdOnlyCentroidIsCoarserThanTheWindowedOne) {
  // centroid_margin_px = 0 weights only the pixels above the threshold, as the seed's
  // binary view would: it still works, but locks to the pixel grid more.
  Scene scene;
  FiducialDetectorOptions threshold_only;
  threshold_only.centroid_margin_px = 0;
  FiducialDetector windowed, plain(threshold_only);
  double windowed_error = 0, plain_error = 0;
  for (int trial = 0; trial < 25; ++trial) {
    const double cx = 100 + (trial % 5) / 5.0, cy = 75 + (trial / 5) / 5.0;
    cv::Mat image = render(scene, {disc(cx, cy, 3.0, 220)});
    const auto& from_window = windowed.detect(image);
    const auto& from_threshold = plain.detect(image);
    ASSERT_EQ(from_window.size(), 1u);
    ASSERT_EQ(from_threshold.size(), 1u);
    windowed_error += std::hypot(from_window[0].x - cx, from_window[0].y - cy);
    plain_error += std::hypot(from_threshold[0].x - cx, from_threshold[0].y - cy);
  }
  EXPECT_LT(windowed_error, plain_error);
  EXPECT_LT(plain_error / 25, 0.1);  // still sub-pixel
}

TEST(FiducialDetector, UncertaintyMatchesTheScatterUnderNoise) {
  Scene scene;
  scene.noise_sigma = 4;
  FiducialDetectorOptions options;
  options.pixel_noise = 4;
  options.sampling_error_px = 0;
  FiducialDetector detector(options);
  const double cx = 100.3, cy = 75.6;
  double squared = 0, predicted = 0;
  int trials = 0;
  for (unsigned seed = 1; seed <= 300; ++seed) {
    scene.noise_seed = seed;
    const auto& found = detector.detect(render(scene, {disc(cx, cy, 3.5, 150)}));
    ASSERT_EQ(found.size(), 1u);
    squared += (std::pow(found[0].x - cx, 2) + std::pow(found[0].y - cy, 2)) / 2;
    predicted += found[0].uncertainty_px;
    ++trials;
  }
  const double scatter = std::sqrt(squared / trials);  // per axis, bias included
  const double mean_predicted = predicted / trials;
  EXPECT_GT(mean_predicted, 0.7 * scatter);
  EXPECT_LT(mean_predicted, 1.3 * scatter);

  // Fainter means less certain; without noise what is left is the sampling error.
  scene.noise_seed = 1;
  const double bright = detector.detect(render(scene, {disc(cx, cy, 3.5, 230)}))[0].uncertainty_px;
  const double faint = detector.detect(render(scene, {disc(cx, cy, 3.5, 80)}))[0].uncertainty_px;
  EXPECT_LT(bright, faint);
  options.sampling_error_px = 0.06;
  options.pixel_noise = 0;
  const DetectedFiducial lone =
      detect_fiducials(render(scene, {disc(cx, cy, 3.5, 230)}), options)[0];
  EXPECT_DOUBLE_EQ(lone.uncertainty_px, 0.06 / std::sqrt(lone.area_px));
}

// Without noise a centroid still keeps some of the pixel grid, the more the smaller the blob;
// the uncertainty says so (FiducialDetectorOptions::sampling_error_px), and does not claim
// less than the error these exactly sampled discs show.
TEST(FiducialDetector, UncertaintyWithoutNoiseFollowsTheBlobSize) {
  Scene scene;
  FiducialDetectorOptions options;
  options.pixel_noise = 0;
  options.min_circularity = 0;
  FiducialDetector detector(options);
  std::vector<double> actual, predicted;
  for (double radius : {0.8, 3.5}) {
    double squared = 0, claimed = 0;
    constexpr int kTrials = 49;
    for (int trial = 0; trial < kTrials; ++trial) {
      const double cx = 100 + (trial % 7) / 7.0, cy = 75 + (trial / 7) / 7.0;
      const auto& found = detector.detect(render(scene, {disc(cx, cy, radius, 200)}));
      ASSERT_EQ(found.size(), 1u);
      squared += (std::pow(found[0].x - cx, 2) + std::pow(found[0].y - cy, 2)) / 2;
      claimed += found[0].uncertainty_px;
    }
    actual.push_back(std::sqrt(squared / kTrials));
    predicted.push_back(claimed / kTrials);
    EXPECT_GE(predicted.back(), actual.back()) << "radius " << radius;
  }
  EXPECT_GT(actual[0], 3 * actual[1]);
  EXPECT_GT(predicted[0], 2 * predicted[1]);
  RecordProperty("small_blob_px", fmt::format("{:.4f} claimed {:.4f}", actual[0], predicted[0]));
  RecordProperty("large_blob_px", fmt::format("{:.4f} claimed {:.4f}", actual[1], predicted[1]));
}

// Markers a few pixels apart share their centroid windows. Each window is cut to a disc on its
// own marker's side, so neither flank pulls the other's centroid; the threshold-only centroid
// it replaced erred by 0.023 px RMS here.
TEST(FiducialDetector, MarkersCloseTogetherKeepTheirOwnCentroids) {
  Scene scene;
  scene.noise_sigma = 1;
  FiducialDetector detector;
  for (double gap : {7.0, 8.0}) {
    double squared = 0;
    constexpr int kTrials = 25;
    for (int trial = 0; trial < kTrials; ++trial) {
      const double cx = 100 + (trial % 5) / 5.0, cy = 75 + (trial / 5) / 5.0;
      scene.noise_seed = static_cast<unsigned>(trial + 1);
      const auto& found = detector.detect(
          render(scene, {disc(cx, cy, 2.0, 220), disc(cx + gap, cy + 0.3 * gap, 2.0, 150)}));
      ASSERT_EQ(found.size(), 2u) << "gap " << gap;
      const DetectedFiducial& left = found[0].x < found[1].x ? found[0] : found[1];
      squared += (std::pow(left.x - cx, 2) + std::pow(left.y - cy, 2)) / 2;
    }
    const double rms = std::sqrt(squared / kTrials);
    EXPECT_LT(rms, 0.015) << "gap " << gap;
    RecordProperty(fmt::format("rms_px_at_gap_{}", gap), fmt::format("{:.4f}", rms));
  }
}

// --- Filters --------------------------------------------------------------------------------

TEST(FiducialDetector, DarkNoisyFrameYieldsNothingAboveTheFloor) {
  Scene scene;
  scene.background = 20;
  scene.noise_sigma = 4;  // the brightest noise pixel is about 36
  cv::Mat image = render(scene, {});
  DetectionStats stats;
  EXPECT_TRUE(detect_fiducials(image, {}, &stats).empty());
  EXPECT_DOUBLE_EQ(stats.threshold, 40);  // the floor, not 0.75 x the peak
  EXPECT_GT(stats.peak, 30);
  EXPECT_EQ(stats.regions, 0);

  // Without the floor the same frame turns noise into "fiducials".
  FiducialDetectorOptions no_floor;
  no_floor.min_threshold = 0;
  EXPECT_FALSE(detect_fiducials(image, no_floor).empty());
}

TEST(FiducialDetector, LampIsRejectedByArea) {
  Scene scene;
  cv::Mat image =
      render(scene, {disc(60, 75, 30, 245), disc(150, 40, 4, 235), disc(160, 110, 4, 235)});
  DetectionStats stats;
  auto found = detect_fiducials(image, {}, &stats);
  ASSERT_EQ(found.size(), 2u);
  EXPECT_NEAR(found[0].x, 150, 0.05);
  EXPECT_NEAR(found[1].x, 160, 0.05);
  EXPECT_EQ(stats.regions, 3);
  EXPECT_EQ(stats.rejected_large, 1);
  EXPECT_EQ(stats.accepted, 2);
}

TEST(FiducialDetector, ElongatedBlobIsRejectedByCircularity) {
  Scene scene;
  const Blob streak{60, 75, 12, 3, 230, 0.5};  // 1:4
  cv::Mat image = render(scene, {streak, disc(150, 75, 4, 230)});
  DetectionStats stats;
  auto found = detect_fiducials(image, {}, &stats);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_NEAR(found[0].x, 150, 0.05);
  EXPECT_EQ(stats.rejected_not_round, 1);

  FiducialDetectorOptions accept_all;
  accept_all.min_circularity = 0;
  auto both = detect_fiducials(image, accept_all);
  ASSERT_EQ(both.size(), 2u);
  std::sort(both.begin(), both.end(), [](const auto& a, const auto& b) { return a.x < b.x; });
  EXPECT_NEAR(both[0].x, 60, 0.05);
  EXPECT_LT(both[0].circularity, 0.6);
  EXPECT_GT(both[1].circularity, 0.9);
}

TEST(FiducialDetector, CircularityOfDigitisedDiscsAndEllipses) {
  Scene scene;
  std::mt19937 random(11);
  std::uniform_real_distribution<double> fraction(0, 1);
  FiducialDetectorOptions accept_all;
  accept_all.min_circularity = 0;
  FiducialDetector detector(accept_all);
  for (double radius : {2.5, 3.0, 4.0, 6.0, 10.0}) {
    for (int trial = 0; trial < 10; ++trial) {
      const double cx = 100 + fraction(random), cy = 75 + fraction(random);
      const auto& found = detector.detect(render(scene, {disc(cx, cy, radius, 230)}));
      ASSERT_EQ(found.size(), 1u);
      EXPECT_GE(found[0].circularity, 0.93) << "disc of radius " << radius;
      EXPECT_LE(found[0].circularity, 1.0) << "disc of radius " << radius;
    }
  }
  for (double angle : {0.0, 0.4, 0.785, 1.2}) {
    const auto& found = detector.detect(render(scene, {{100, 75, 16, 4, 230, angle}}));
    ASSERT_EQ(found.size(), 1u);
    EXPECT_LT(found[0].circularity, 0.6) << "1:4 ellipse at " << angle << " rad";
  }
}

TEST(FiducialDetector, IsolatedHotPixelIsRejectedByMinimumArea) {
  Scene scene;
  cv::Mat image = render(scene, {disc(100, 75, 4, 235)});
  image.at<uint8_t>(20, 30) = 255;  // the brightest pixel of the frame
  DetectionStats stats;
  auto found = detect_fiducials(image, {}, &stats);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_NEAR(found[0].x, 100, 0.05);
  EXPECT_EQ(stats.peak, 255);
  EXPECT_EQ(stats.rejected_small, 1);
}

TEST(FiducialDetector, SmallBlobsAreNotJudgedByCircularity) {
  // A far marker of 3-11 pixels may be any shape on the grid; it is kept.
  cv::Mat image(40, 40, CV_8U, cv::Scalar(0));
  image(cv::Rect(10, 10, 4, 1)).setTo(200);  // a 4-pixel line: not round at all
  FiducialDetectorOptions options;
  options.min_circularity = 0.9;
  auto found = detect_fiducials(image, options);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_LT(found[0].circularity, 0.9);
  options.circularity_min_area_px = 4;
  EXPECT_TRUE(detect_fiducials(image, options).empty());
}

TEST(FiducialDetector, RegionOfInterestIsRespected) {
  Scene scene;
  cv::Mat image = render(scene, {disc(40, 40, 4, 150), disc(150, 100, 4, 150)});
  image(cv::Rect(180, 10, 10, 10)).setTo(255);  // a saturated lamp outside the ROI
  FiducialDetectorOptions options;
  options.region_of_interest = cv::Rect(100, 50, 100, 100);
  DetectionStats stats;
  auto found = detect_fiducials(image, options, &stats);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_NEAR(found[0].x, 150, 0.05);  // full-image coordinates
  EXPECT_NEAR(found[0].y, 100, 0.05);
  // The threshold comes from the ROI's brightest pixel, not the lamp's.
  EXPECT_LT(stats.peak, 255);

  // Clipped to the image; wholly outside it, nothing (not the whole image).
  options.region_of_interest = cv::Rect(100, 50, 1000, 1000);
  EXPECT_EQ(detect_fiducials(image, options).size(), 1u);
  options.region_of_interest = cv::Rect(500, 500, 10, 10);
  EXPECT_TRUE(detect_fiducials(image, options).empty());
}

TEST(FiducialDetector, BlobsTouchingTheBorderAreFlaggedOrRejected) {
  Scene scene;
  cv::Mat image = render(scene, {disc(0.5, 75, 4, 230), disc(199, 149, 4, 230),
                                 disc(100, 0, 4, 230), disc(100, 75, 4, 230)});
  auto found = detect_fiducials(image);
  ASSERT_EQ(found.size(), 4u);
  int at_border = 0;
  for (const DetectedFiducial& fiducial : found) {
    EXPECT_GE(fiducial.x, 0);
    EXPECT_GE(fiducial.y, 0);
    EXPECT_LE(fiducial.x, 199);
    EXPECT_LE(fiducial.y, 149);
    if (fiducial.touches_border) ++at_border;
  }
  EXPECT_EQ(at_border, 3);

  FiducialDetectorOptions options;
  options.reject_border_regions = true;
  DetectionStats stats;
  found = detect_fiducials(image, options, &stats);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_NEAR(found[0].x, 100, 0.05);
  EXPECT_EQ(stats.rejected_at_border, 3);

  // The ROI's edge counts as a border too: the middle disc is cut by its left edge.
  options.region_of_interest = cv::Rect(100, 0, 100, 150);
  EXPECT_TRUE(detect_fiducials(image, options, &stats).empty());
  EXPECT_EQ(stats.rejected_at_border, 3);
}

TEST(FiducialDetector, WholeFrameAboveThresholdIsOneRegion) {
  cv::Mat image(30, 40, CV_8U, cv::Scalar(200));
  FiducialDetectorOptions options;
  options.max_area_px = 100000;
  options.min_circularity = 0;
  auto found = detect_fiducials(image, options);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_DOUBLE_EQ(found[0].area_px, 1200);
  EXPECT_TRUE(found[0].touches_border);
}

// --- Agreement with OpenCV ------------------------------------------------------------------

// Random binary speckle: every kind of region shape, merge order and hole.
cv::Mat speckle(int width, int height, double density, unsigned seed) {
  cv::Mat image(height, width, CV_8U);
  std::mt19937 random(seed);
  std::bernoulli_distribution bright(density);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) image.at<uint8_t>(y, x) = bright(random) ? 200 : 0;
  }
  return image;
}

FiducialDetectorOptions accept_everything(int connectivity) {
  FiducialDetectorOptions options;
  options.min_area_px = 1;
  options.max_area_px = 1 << 30;
  options.min_circularity = 0;
  options.centroid_margin_px = 0;  // centroids of the regions' own pixels
  options.connectivity = connectivity;
  return options;
}

TEST(FiducialDetector, RegionsMatchOpenCvConnectedComponents) {
  for (int connectivity : {4, 8}) {
    for (unsigned seed = 1; seed <= 6; ++seed) {
      cv::Mat image = speckle(97, 61, 0.15 + 0.08 * seed, seed);
      auto found = detect_fiducials(image, accept_everything(connectivity));

      cv::Mat labels, stats, centroids;
      const int labels_count =
          cv::connectedComponentsWithStats(image > 100, labels, stats, centroids, connectivity);
      ASSERT_EQ(found.size(), static_cast<size_t>(labels_count - 1))
          << "connectivity " << connectivity << ", seed " << seed;
      // Uniform brightness: the weighted centroid is the plain one.
      std::vector<std::tuple<double, double, double>> ours, theirs;
      for (const auto& f : found) ours.emplace_back(f.area_px, f.x, f.y);
      for (int label = 1; label < labels_count; ++label) {
        theirs.emplace_back(stats.at<int>(label, cv::CC_STAT_AREA), centroids.at<double>(label, 0),
                            centroids.at<double>(label, 1));
      }
      std::sort(ours.begin(), ours.end());
      std::sort(theirs.begin(), theirs.end());
      for (size_t i = 0; i < ours.size(); ++i) {
        EXPECT_EQ(std::get<0>(ours[i]), std::get<0>(theirs[i]));
        EXPECT_NEAR(std::get<1>(ours[i]), std::get<1>(theirs[i]), 1e-9);
        EXPECT_NEAR(std::get<2>(ours[i]), std::get<2>(theirs[i]), 1e-9);
      }
    }
  }
}

TEST(FiducialDetector, CircularityIsThatOfTheSubPixelOutlineAtTheThreshold) {
  // A uniform block of 200 on black, threshold 150: the outline crosses a quarter of the way
  // from the outer pixel centres to the next ones, and cuts the corners' cells diagonally.
  auto block_circularity = [](int width, int height) {
    cv::Mat image(40, 40, CV_8U, cv::Scalar(0));
    image(cv::Rect(10, 10, width, height)).setTo(200);
    FiducialDetectorOptions options = accept_everything(8);
    options.threshold_ratio = 0.75;
    auto found = detect_fiducials(image, options);
    EXPECT_EQ(found.size(), 1u);
    return found.empty() ? 0.0 : found[0].circularity;
  };
  auto expected = [](int width, int height) {
    const double w = width - 1 + 0.5, h = height - 1 + 0.5, cut = 0.25;
    const double area = w * h - 4 * cut * cut / 2;
    const double length = 2 * (w - 2 * cut) + 2 * (h - 2 * cut) + 4 * cut * std::numbers::sqrt2;
    return 4 * std::numbers::pi * area / (length * length);
  };
  EXPECT_NEAR(block_circularity(5, 5), expected(5, 5), 1e-6);        // 0.834
  EXPECT_NEAR(block_circularity(3, 12), expected(3, 12), 1e-6);      // 0.479
  EXPECT_NEAR(block_circularity(1, 1), std::numbers::pi / 4, 1e-6);  // a diamond

  // Diagonal neighbours: one region joined across the saddle under 8-connectivity.
  cv::Mat pair(20, 20, CV_8U, cv::Scalar(0));
  pair.at<uint8_t>(8, 8) = pair.at<uint8_t>(9, 9) = 200;
  auto joined = detect_fiducials(pair, accept_everything(8));
  ASSERT_EQ(joined.size(), 1u);
  EXPECT_GT(joined[0].circularity, 0.3);
  EXPECT_LT(joined[0].circularity, std::numbers::pi / 4);
  EXPECT_EQ(detect_fiducials(pair, accept_everything(4)).size(), 2u);
}

// --- Behaviour ------------------------------------------------------------------------------

TEST(FiducialDetector, ResultsDoNotDependOnStepOrEarlierFrames) {
  Scene scene;
  scene.noise_sigma = 2;
  cv::Mat big = render(scene, {disc(40, 40, 4, 230), disc(150, 100, 3, 230)});
  cv::Mat view = big(cv::Rect(20, 20, 160, 110));  // not continuous
  cv::Mat copy = view.clone();
  FiducialDetector detector;
  detector.detect(render(scene, {disc(100, 75, 20, 250)}));  // something else first
  std::vector<DetectedFiducial> from_view = detector.detect(view);
  std::vector<DetectedFiducial> from_copy = detect_fiducials(copy);
  ASSERT_EQ(from_view.size(), 2u);
  ASSERT_EQ(from_copy.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_DOUBLE_EQ(from_view[i].x, from_copy[i].x);
    EXPECT_DOUBLE_EQ(from_view[i].y, from_copy[i].y);
  }
  EXPECT_NEAR(from_view[0].x, 20, 0.05);  // coordinates of the image it was given
}

TEST(FiducialDetector, RejectsBadOptionsAndImages) {
  auto invalid = [](auto change) {
    FiducialDetectorOptions options;
    change(options);
    EXPECT_THROW(FiducialDetector{options}, std::invalid_argument);
  };
  invalid([](auto& o) { o.threshold_ratio = 1.5; });
  invalid([](auto& o) { o.min_threshold = -1; });
  invalid([](auto& o) { o.min_area_px = 0; });
  invalid([](auto& o) { o.max_area_px = 2; });
  invalid([](auto& o) { o.min_circularity = 2; });
  invalid([](auto& o) { o.connectivity = 6; });
  invalid([](auto& o) { o.region_of_interest = cv::Rect(0, 0, -5, 10); });
  invalid([](auto& o) { o.centroid_level = -0.1; });
  FiducialDetectorOptions options;
  EXPECT_EQ(options.problem(), std::nullopt);
  options.connectivity = 6;
  EXPECT_EQ(options.problem(), "connectivity: 6; 4 or 8");
  options = {};
  options.max_area_px = 2;
  EXPECT_EQ(options.problem(), "max_area_px: 2 is below min_area_px, 3");
  try {
    FiducialDetector detector(options);
    ADD_FAILURE() << "max_area_px below min_area_px accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "FiducialDetectorOptions::max_area_px: 2 is below min_area_px, 3");
  }
  EXPECT_THROW(detect_fiducials(cv::Mat(10, 10, CV_8UC3, cv::Scalar::all(0))),
               std::invalid_argument);
  EXPECT_THROW(detect_fiducials(cv::Mat(10, 10, CV_16U, cv::Scalar(0))), std::invalid_argument);
  EXPECT_TRUE(detect_fiducials(cv::Mat()).empty());
}

// --- Image messages -------------------------------------------------------------------------

sensor_msgs::msg::Image image_message(const cv::Mat& mono8) {
  sensor_msgs::msg::Image message;
  fill_image_message(mono8, message);
  return message;
}

TEST(ImageMessage, RoundTripGivesTheSameFiducials) {
  Scene scene;
  cv::Mat image = render(scene, {disc(40, 40, 4, 230), disc(150, 100, 3, 230)});
  sensor_msgs::msg::Image message = image_message(image);
  Mono8View view = view_mono8(message);
  ASSERT_TRUE(view.problem.empty()) << view.problem;
  auto direct = detect_fiducials(image);
  auto through_message = detect_fiducials(view.pixels);
  ASSERT_EQ(direct.size(), through_message.size());
  for (size_t i = 0; i < direct.size(); ++i) EXPECT_DOUBLE_EQ(direct[i].x, through_message[i].x);
}

TEST(ImageMessage, UnreadableImagesSayWhy) {
  const sensor_msgs::msg::Image good = image_message(cv::Mat(20, 30, CV_8U, cv::Scalar(5)));
  auto problem = [](const sensor_msgs::msg::Image& message) {
    Mono8View view = view_mono8(message);
    EXPECT_TRUE(view.pixels.empty());
    return view.problem;
  };
  EXPECT_TRUE(view_mono8(good).problem.empty());

  sensor_msgs::msg::Image wrong_encoding = good;
  wrong_encoding.encoding("rgb8");
  EXPECT_NE(problem(wrong_encoding).find("encoding 'rgb8'"), std::string::npos);

  sensor_msgs::msg::Image zero_size = good;
  zero_size.width(0);
  EXPECT_NE(problem(zero_size).find("empty"), std::string::npos);

  sensor_msgs::msg::Image short_step = good;
  short_step.step(29);
  EXPECT_NE(problem(short_step).find("step 29"), std::string::npos);

  sensor_msgs::msg::Image short_data = good;
  short_data.data().resize(30 * 19);
  EXPECT_NE(problem(short_data).find("570 bytes"), std::string::npos);
}

// --- The plugin -----------------------------------------------------------------------------

std::filesystem::path plugin_library(const std::string& plugin) {
  return test::plugin_dir() / ("libmocap_plugin_" + plugin + ".so");
}

// The plugin's factory, or nullptr when the library is not built or cannot be loaded.
const ComponentFactory* load_plugin(const std::string& plugin) {
  // Never closed: the factory and its code must outlive every host that uses them.
  void* library = dlopen(plugin_library(plugin).c_str(), RTLD_NOW | RTLD_LOCAL);
  if (library == nullptr) return nullptr;
  auto entry =
      reinterpret_cast<const ComponentFactory* (*)()>(dlsym(library, ComponentFactory::kSymbol));
  return entry == nullptr ? nullptr : entry();
}

class ImagePublisher final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.publishes<sensor_msgs::msg::Image>("/camera/ir/image_raw", Qos::sensor_data(), "");
  }
  explicit ImagePublisher(Context& context) : Component(context) {
    publisher = create_publisher<sensor_msgs::msg::Image>("/camera/ir/image_raw");
  }
  Publisher<sensor_msgs::msg::Image> publisher;
};

class FiducialCollector final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.subscribes<mocap_msgs::msg::FiducialArray>("/mocap/fiducials", Qos::reliable(), "");
  }
  explicit FiducialCollector(Context& context) : Component(context) {
    create_subscription<mocap_msgs::msg::FiducialArray>(
        "/mocap/fiducials", [this](const mocap_msgs::msg::FiducialArray& array) {
          std::lock_guard lock(mutex_);
          arrays_.push_back(array);
          arrived_.notify_all();
        });
  }
  // The first `count` arrays, waiting for them up to `timeout` (not a timing assertion: a
  // generous bound so that a broken plugin fails instead of hanging).
  std::vector<mocap_msgs::msg::FiducialArray> wait_for(size_t count, std::chrono::seconds timeout) {
    std::unique_lock lock(mutex_);
    arrived_.wait_for(lock, timeout, [&] { return arrays_.size() >= count; });
    return arrays_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable arrived_;
  std::vector<mocap_msgs::msg::FiducialArray> arrays_;
};

TEST(FiducialTrackerPlugin, PublishesAnArrayPerReadableImageAndDropsTheOthers) {
  const ComponentFactory* tracker = load_plugin("fiducial_tracker");
  ASSERT_NE(tracker, nullptr) << "mocap_plugin_fiducial_tracker did not load";

  Scene scene;
  cv::Mat frame = render(scene, {disc(40.25, 30.5, 4, 230), disc(150, 100, 3, 230)});
  sensor_msgs::msg::Image good = image_message(frame);
  good.header().frame_id("camera_ir_optical");
  good.header().stamp().sec(12);
  good.header().stamp().nanosec(345);
  sensor_msgs::msg::Image colour = good;
  colour.encoding("bgr8");
  sensor_msgs::msg::Image truncated = good;
  truncated.data().resize(100);

  testing::internal::CaptureStderr();
  std::vector<mocap_msgs::msg::FiducialArray> arrays;
  {
    ComponentHost host({.name = "test", .threads = 1, .dds = {.enabled = false}});
    host.add(*tracker, {.name = "tracker"});
    auto& camera = static_cast<ImagePublisher&>(
        host.add(make_component_factory<ImagePublisher>("images"), {.name = "camera"}));
    auto& collector = static_cast<FiducialCollector&>(
        host.add(make_component_factory<FiducialCollector>("collector"), {.name = "collector"}));
    host.start();
    // One queue, served in order: when the array of `good` arrives, both drops are counted.
    for (const auto* image : {&colour, &truncated, &good}) camera.publisher.publish(*image);
    arrays = collector.wait_for(1, std::chrono::seconds(30));
    EXPECT_EQ(host.callback_errors(), 0u);
  }
  const std::string log = testing::internal::GetCapturedStderr();

  ASSERT_EQ(arrays.size(), 1u) << log;
  const auto& array = arrays[0];
  EXPECT_EQ(array.header().frame_id(), "camera_ir_optical");
  EXPECT_EQ(array.header().stamp().sec(), 12);
  EXPECT_EQ(array.header().stamp().nanosec(), 345u);
  ASSERT_EQ(array.fiducials().size(), 2u);
  const auto expected = detect_fiducials(frame);
  for (size_t i = 0; i < 2; ++i) {
    const auto& fiducial = array.fiducials()[i];
    EXPECT_FLOAT_EQ(fiducial.x(), static_cast<float>(expected[i].x));
    EXPECT_FLOAT_EQ(fiducial.y(), static_cast<float>(expected[i].y));
    EXPECT_EQ(fiducial.z(), 0.0f);
    EXPECT_FLOAT_EQ(fiducial.size(), static_cast<float>(expected[i].area_px));
    EXPECT_FLOAT_EQ(fiducial.uncertainty(), static_cast<float>(expected[i].uncertainty_px));
  }
  EXPECT_NEAR(array.fiducials()[0].x(), 40.25, 0.05);
  // The first drop is logged at once with its reason; the closing summary counts both.
  EXPECT_NE(log.find("dropped 1 unreadable image(s) on /camera/ir/image_raw (1 in all): "
                     "encoding 'bgr8' is not supported"),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("1 images in all, 2.0 fiducials per image, 2 dropped"), std::string::npos)
      << log;
}

// camera_source reads rendered frames from a directory, fiducial_tracker finds their markers;
// the tracker's closing summary says how many it found per image.
TEST(FiducialTrackerPlugin, FindsTheMarkersOfImagesFromADirectory) {
  test::TempDir dir;
  std::filesystem::create_directory(dir / "frames");
  Scene scene;
  scene.noise_sigma = 2;
  for (int i = 0; i < 6; ++i) {
    scene.noise_seed = static_cast<unsigned>(i + 1);
    cv::Mat frame =
        render(scene, {disc(30 + i, 30, 4, 230), disc(100, 80, 3, 230), disc(170, 120, 5, 230)});
    ASSERT_TRUE(cv::imwrite((dir / "frames" / fmt::format("frame_{:03}.png", i)).string(), frame));
  }
  test::write_file(dir / "graph.yaml", fmt::format(R"(dds: {{enabled: false}}
groups:
  - name: tracking
    components:
      - plugin: fiducial_tracker
        name: tracker
        parameters: {{roi: [], report_period_s: 60}}
      - plugin: camera_source
        name: camera
        parameters: {{directory: "{}", rate_hz: 100}}
)",
                                                   (dir / "frames").string()));
  auto [code, output] = test::run_command({(test::bin_dir() / "mocap_launch").string(),
                                           (dir / "graph.yaml").string(), "--duration", "3"});
  EXPECT_EQ(code, 0) << output;
  EXPECT_NE(output.find("end of input after 6 frames"), std::string::npos) << output;
  EXPECT_NE(output.find("3.0 fiducials per image, 0 dropped"), std::string::npos) << output;
}

}  // namespace
}  // namespace mocap::tracking
