// CalibrationCoverage: each camera's image as nine regions filled by the board's sightings, and
// the shots shared with another camera, with what is missing named.
#include <gtest/gtest.h>

#include <stdexcept>

#include "volume/volume_calibration/calibration_coverage.hpp"

namespace mocap::volume {
namespace {

const std::vector<CoverageCamera> kCameras = {
    {"cam_0", {1200, 900}}, {"cam_1", {1200, 900}}, {"cam_2", {640, 480}}};

// A sighting by `camera` at `stamp_ns` of a board of `pixels` (nullopt: a marker not seen).
BoardSighting sighting(size_t camera, int64_t stamp_ns,
                       std::vector<std::optional<Eigen::Vector2d>> pixels) {
  return {stamp_ns, camera, std::move(pixels)};
}

TEST(CalibrationCoverage, ASightingCountsOnceInEachRegionItTouches) {
  CalibrationCoverage coverage(kCameras, {.views_per_region = 2, .shared_shots = 1});
  // Two markers in the upper left, one on the right edge, one off the image, one not seen.
  coverage.add(sighting(0, 0,
                        {Eigen::Vector2d(10, 10), Eigen::Vector2d(390, 290),
                         Eigen::Vector2d(1190, 450), Eigen::Vector2d(1300, 10), std::nullopt}));
  const CameraCoverage& cam_0 = coverage.cameras()[0];
  EXPECT_EQ(cam_0.views[0], 1u);  // upper left corner, once for its two markers
  EXPECT_EQ(cam_0.views[5], 1u);  // right edge
  for (int r : {1, 2, 3, 4, 6, 7, 8}) EXPECT_EQ(cam_0.views[static_cast<size_t>(r)], 0u) << r;
  EXPECT_EQ(cam_0.shared_shots, 0u);
  // 2 of the 9 x 2 views and 0 of 1 shared shot.
  EXPECT_DOUBLE_EQ(cam_0.progress, 2.0 / 19);
  EXPECT_EQ(cam_0.missing, (std::vector<std::string>{
                               "upper left corner", "top edge", "upper right corner", "left edge",
                               "centre", "right edge", "lower left corner", "bottom edge",
                               "lower right corner", "shots with another camera"}));
  coverage.add(sighting(0, 1'000'000'000, {Eigen::Vector2d(100, 100)}));
  EXPECT_EQ(coverage.cameras()[0].views[0], 2u);
  EXPECT_EQ(coverage.cameras()[0].missing.front(), "top edge");  // the upper left corner is full
  EXPECT_EQ(coverage.cameras()[1].views[0], 0u);                 // cameras apart
}

TEST(CalibrationCoverage, AShotIsSharedWhenAnotherCameraSawTheWholeBoardWithinACaptureTime) {
  CalibrationCoverage coverage(kCameras);
  const std::vector<std::optional<Eigen::Vector2d>> whole = {Eigen::Vector2d(300, 200),
                                                             Eigen::Vector2d(320, 220)};
  std::vector<std::optional<Eigen::Vector2d>> partial = whole;
  partial[1].reset();
  // t = 0: cam_0 whole, cam_1 whole 1 ms later (one capture time): both gain a shot; cam_2
  // partly: not it.
  coverage.add(sighting(0, 0, whole));
  EXPECT_EQ(coverage.cameras()[0].shared_shots, 0u);
  coverage.add(sighting(1, 1'000'000, whole));
  coverage.add(sighting(2, 0, partial));
  EXPECT_EQ(coverage.cameras()[0].shared_shots, 1u);
  EXPECT_EQ(coverage.cameras()[1].shared_shots, 1u);
  EXPECT_EQ(coverage.cameras()[2].shared_shots, 0u);
  // cam_2 whole at the same capture time: its own shot, the others' counted once already.
  coverage.add(sighting(2, 500'000, whole));
  EXPECT_EQ(coverage.cameras()[2].shared_shots, 1u);
  EXPECT_EQ(coverage.cameras()[0].shared_shots, 1u);
  // 5 ms apart: two capture times, nothing shared.
  coverage.add(sighting(0, 100'000'000, whole));
  coverage.add(sighting(1, 105'000'000, whole));
  EXPECT_EQ(coverage.cameras()[0].shared_shots, 1u);
  EXPECT_EQ(coverage.cameras()[1].shared_shots, 1u);
  // The same camera twice at one capture time counts once.
  coverage.add(sighting(1, 105'500'000, whole));
  EXPECT_EQ(coverage.cameras()[1].shared_shots, 1u);
}

TEST(CalibrationCoverage, ASessionIsCompleteWhenItsLeastCoveredCameraIs) {
  const CoverageOptions options{.views_per_region = 3, .shared_shots = 4};
  CalibrationCoverage coverage(kCameras, options);
  // cam_0 and cam_1: the board in every region of their images, at the same capture times.
  for (int shot = 0; shot < 12; ++shot) {
    const int region = shot % kCoverageRegions;
    const Eigen::Vector2d centre(200 + 400 * (region % 3), 150 + 300 * (region / 3));
    for (size_t c : {0u, 1u}) coverage.add(sighting(c, shot * 33'000'000, {centre}));
  }
  // Each region seen once or twice: not enough yet.
  EXPECT_LT(coverage.cameras()[0].progress, 1);
  for (int shot = 12; shot < 27; ++shot) {
    const int region = shot % kCoverageRegions;
    const Eigen::Vector2d centre(200 + 400 * (region % 3), 150 + 300 * (region / 3));
    for (size_t c : {0u, 1u}) coverage.add(sighting(c, shot * 33'000'000, {centre}));
  }
  EXPECT_DOUBLE_EQ(coverage.cameras()[0].progress, 1);
  EXPECT_TRUE(coverage.cameras()[0].missing.empty());
  EXPECT_DOUBLE_EQ(coverage.cameras()[1].progress, 1);
  // cam_2 saw nothing: the session is as far as it.
  EXPECT_DOUBLE_EQ(coverage.progress(), 0);
  EXPECT_EQ(coverage.cameras()[2].missing.size(), 10u);
}

TEST(CalibrationCoverage, OptionsAndImagesThatCannotBeUsedAreNamed) {
  try {
    CalibrationCoverage coverage(kCameras, {.views_per_region = 0});
    FAIL() << "views_per_region 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("views_per_region: 0"), std::string::npos) << e.what();
  }
  try {
    CalibrationCoverage coverage({{"cam_9", {0, 480}}});
    FAIL() << "an image of no size accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("camera cam_9: an image of 0x480"), std::string::npos)
        << e.what();
  }
}

TEST(CalibrationCoverage, ProgressBarShowsTheFraction) {
  EXPECT_EQ(progress_bar(0.0, 10), "[          ]   0 %");
  EXPECT_EQ(progress_bar(0.456, 10), "[====      ]  45 %");
  EXPECT_EQ(progress_bar(1.0, 10), "[==========] 100 %");
  EXPECT_EQ(progress_bar(1.7, 4), "[====] 100 %");
}

}  // namespace
}  // namespace mocap::volume
