// Speed and accuracy of the fiducial detector (components/tracking/fiducial_tracker) against the
// seed's method in OpenCV (seed 000 §5.7: cv::threshold at 0.75 x the brightest pixel,
// cv::findContours of the external contours, the mean of each contour's points as the
// centroid, area and circularity filters), both measured in the same run on the same frames,
// on one core (OpenCV's own threads are turned off).
//
//   build/bin/fiducial_tracker_bench            # about a minute and a half
//   build/bin/fiducial_tracker_bench --quick    # a few seconds
//
// Frames are 1280x720 mono8: anti-aliased discs (radius 2.5-5 px, drawn 16x larger with
// cv::circle and area-averaged down, so each pixel holds the disc's exact coverage; a
// cv::circle LINE_AA disc drawn at scale is itself off-centre by up to 0.05 px), blurred by
// the optics (σ 1 px), on a dim background with noise (σ 2 grey levels).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <random>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "tracking/fiducial_tracker/fiducial_tracker.hpp"

namespace {

using Steady = std::chrono::steady_clock;
using mocap::tracking::DetectedFiducial;
using mocap::tracking::FiducialDetector;

constexpr int kWidth = 1280;
constexpr int kHeight = 720;
constexpr double kBlurSigma = 1.0;
constexpr double kBackground = 12;
constexpr double kNoiseSigma = 2;
constexpr int kSupersampling = 16;

struct Frame {
  cv::Mat pixels;
  std::vector<cv::Point2d> centres;
};

// Adds a disc of `radius` centred at `centre` (the centre of the top-left pixel is 0, 0) to
// `image` (CV_32F): drawn kSupersampling times larger on a patch, then area-averaged.
void add_disc(cv::Mat& image, cv::Point2d centre, double radius, double brightness) {
  const int half = static_cast<int>(std::ceil(radius)) + 2;
  const int left = static_cast<int>(std::floor(centre.x)) - half;
  const int top = static_cast<int>(std::floor(centre.y)) - half;
  const int size = 2 * half + 1;
  cv::Mat fine(size * kSupersampling, size * kSupersampling, CV_32F, cv::Scalar(0));
  // Pixel (left, top) covers [left - 0.5, left + 0.5) and fine pixel 0 its first 16th;
  // cv::circle's centres are pixel centres, with 8 fractional bits.
  constexpr int kShift = 8;
  auto to_fine = [](double coarse, int origin) {
    return std::lround(((coarse - origin + 0.5) * kSupersampling - 0.5) * (1 << kShift));
  };
  cv::circle(fine, cv::Point(to_fine(centre.x, left), to_fine(centre.y, top)),
             static_cast<int>(std::lround(radius * kSupersampling * (1 << kShift))),
             cv::Scalar(brightness), cv::FILLED, cv::LINE_AA, kShift);
  cv::Mat coarse;
  cv::resize(fine, coarse, cv::Size(size, size), 0, 0, cv::INTER_AREA);
  image(cv::Rect(left, top, size, size)) += coarse;
}

Frame render_frame(int count, std::mt19937& random) {
  std::uniform_real_distribution<double> unit(0, 1);
  Frame frame;
  cv::Mat image(kHeight, kWidth, CV_32F, cv::Scalar(kBackground));
  // Markers on a jittered grid, so that none touch.
  const int columns = static_cast<int>(std::ceil(std::sqrt(count * 16.0 / 9.0)));
  const int rows = (count + columns - 1) / columns;
  const double cell_width = (kWidth - 40.0) / columns, cell_height = (kHeight - 40.0) / rows;
  for (int i = 0; i < count; ++i) {
    const double radius = 2.5 + 2.5 * unit(random);
    const double jitter = std::min(cell_width, cell_height) / 2 - radius - 8;
    cv::Point2d centre{20 + cell_width * (i % columns + 0.5) + jitter * (2 * unit(random) - 1),
                       20 + cell_height * (i / columns + 0.5) + jitter * (2 * unit(random) - 1)};
    add_disc(image, centre, radius, 200 + 40 * unit(random));
    frame.centres.push_back(centre);
  }
  cv::GaussianBlur(image, image, cv::Size(0, 0), kBlurSigma);
  cv::Mat noise(image.size(), CV_32F);
  cv::randn(noise, 0, kNoiseSigma);
  image += noise;
  image.convertTo(frame.pixels, CV_8U);
  return frame;
}

// The seed's method, as OpenCV gives it.
std::vector<cv::Point2d> seed_detect(const cv::Mat& image, cv::Mat& binary,
                                     std::vector<std::vector<cv::Point>>& contours) {
  double peak = 0;
  cv::minMaxLoc(image, nullptr, &peak);
  cv::threshold(image, binary, 0.75 * peak, 255, cv::THRESH_BINARY);
  cv::findContours(binary, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  std::vector<cv::Point2d> centroids;
  for (const auto& contour : contours) {
    const double area = cv::contourArea(contour);
    const double perimeter = cv::arcLength(contour, true);
    if (area > 2000) continue;  // lamps and reflections
    const double circularity =
        perimeter > 0 ? 4 * std::numbers::pi * area / (perimeter * perimeter) : 0;
    if (circularity < 0.6) continue;  // the seed used 0.75; 0.6 as ours
    cv::Point2d sum(0, 0);
    for (const cv::Point& point : contour) sum += cv::Point2d(point.x, point.y);
    centroids.push_back(sum / static_cast<double>(contour.size()));
  }
  return centroids;
}

struct Accuracy {
  double found = 0;       // fraction of true centres with a detection within 1.5 px
  double mean_error = 0;  // over those
};

Accuracy accuracy(const std::vector<Frame>& frames,
                  const std::vector<std::vector<cv::Point2d>>& detections) {
  double errors = 0, matched = 0, total = 0;
  for (size_t f = 0; f < frames.size(); ++f) {
    for (const cv::Point2d& truth : frames[f].centres) {
      ++total;
      double best = 1e9;
      for (const cv::Point2d& found : detections[f]) best = std::min(best, cv::norm(found - truth));
      if (best < 1.5) {
        errors += best;
        ++matched;
      }
    }
  }
  return {matched / total, matched > 0 ? errors / matched : 0};
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  cv::setNumThreads(1);
  const int frames_per_count = quick ? 4 : 8;
  const int rounds = quick ? 5 : 21;
  const auto round_time = std::chrono::milliseconds(quick ? 100 : 500);

  std::printf(
      "fiducial detection, 1280x720 mono8, one core; ours vs the seed's method in OpenCV\n");
  std::printf("(median of %d interleaved rounds; error = distance to the true centre, px)\n\n",
              rounds);
  std::printf("%10s | %9s %9s %7s %9s | %12s %7s %9s | %8s\n", "fiducials", "ours us", "ours f/s",
              "found", "error", "OpenCV us", "found", "error", "speed-up");

  std::mt19937 random(2014);
  for (int count : {6, 12, 38, 100}) {
    std::vector<Frame> frames;
    for (int i = 0; i < frames_per_count; ++i) frames.push_back(render_frame(count, random));

    FiducialDetector detector;
    cv::Mat binary;
    std::vector<std::vector<cv::Point>> contours;
    std::vector<std::vector<cv::Point2d>> ours(frames.size()), seed(frames.size());
    for (size_t f = 0; f < frames.size(); ++f) {
      for (const DetectedFiducial& d : detector.detect(frames[f].pixels)) {
        ours[f].emplace_back(d.x, d.y);
      }
      seed[f] = seed_detect(frames[f].pixels, binary, contours);
    }

    // Each round runs both for about round_time, one after the other, so that both see the
    // same state of a shared machine.
    auto time_per_frame = [&](auto&& detect_one) {
      size_t runs = 0;
      auto start = Steady::now();
      do {
        for (const Frame& frame : frames) detect_one(frame.pixels);
        runs += frames.size();
      } while (Steady::now() - start < round_time);
      return std::chrono::duration<double, std::micro>(Steady::now() - start).count() / runs;
    };
    std::vector<double> ours_us, seed_us;
    size_t sink = 0;
    for (int round = 0; round < rounds; ++round) {
      ours_us.push_back(
          time_per_frame([&](const cv::Mat& image) { sink += detector.detect(image).size(); }));
      seed_us.push_back(time_per_frame(
          [&](const cv::Mat& image) { sink += seed_detect(image, binary, contours).size(); }));
    }
    const double our_time = median(ours_us), seed_time = median(seed_us);
    const Accuracy our_accuracy = accuracy(frames, ours), seed_accuracy = accuracy(frames, seed);
    std::printf("%10d | %9.1f %9.0f %6.1f%% %9.4f | %12.1f %6.1f%% %9.4f | %7.1fx\n", count,
                our_time, 1e6 / our_time, 100 * our_accuracy.found, our_accuracy.mean_error,
                seed_time, 100 * seed_accuracy.found, seed_accuracy.mean_error,
                seed_time / our_time);
    if (sink == 0) std::printf("(nothing found)\n");
  }
  return 0;
}
