// The evaluator's bookkeeping and the overlay's drawing.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include <mocap/calibration/pinhole_camera.hpp>
#include <opencv2/core.hpp>

#include "tracking/overlay/overlay.hpp"
#include "tracking/pose_evaluator/pose_evaluator.hpp"

namespace mocap {
namespace {

using evaluation::EvaluationSummary;
using evaluation::ObjectPose;
using evaluation::PoseEvaluator;

ObjectPose at(const std::string& name, double x, double z, int visible = 12) {
  ObjectPose pose;
  pose.name = name;
  pose.pose.translation() = Eigen::Vector3d(x, 0, z);
  pose.visible_markers = visible;
  return pose;
}

TEST(PoseEvaluator, PairsByStampInAnyOrder) {
  PoseEvaluator evaluator;
  evaluator.add_truth(1, {at("a", 0, 2), at("b", 1, 2)});
  evaluator.add_estimate(2, {at("a", 0.003, 2)});  // before its truth
  evaluator.add_estimate(1, {at("a", 0.001, 2), at("b", 1, 2.002)});
  evaluator.add_truth(2, {at("a", 0, 2)});
  const EvaluationSummary& total = evaluator.total();
  EXPECT_EQ(total.frames, 2u);
  EXPECT_EQ(total.expected, 3u);
  EXPECT_EQ(total.tracked, 3u);
  EXPECT_EQ(total.false_identifications, 0u);
  ASSERT_EQ(total.position_errors_m.size(), 3u);
  EXPECT_NEAR(EvaluationSummary::quantile(total.position_errors_m, 0.5), 0.002, 1e-12);
  EXPECT_DOUBLE_EQ(total.tracked_percent(), 100.0);
}

TEST(PoseEvaluator, CountsMissesFalseIdentificationsAndLostFrames) {
  evaluation::EvaluationOptions options;
  options.max_pending_frames = 2;
  PoseEvaluator evaluator(options);
  // A board in view but not found; one with too few visible markers is not expected.
  evaluator.add_truth(1, {at("a", 0, 2), at("b", 1, 2, 4)});
  evaluator.add_estimate(1, {at("c", 0, 2), at("a", 0.2, 2)});  // c not in view, a far off
  EXPECT_EQ(evaluator.total().expected, 1u);
  EXPECT_EQ(evaluator.total().tracked, 0u);
  EXPECT_EQ(evaluator.total().false_identifications, 2u);
  // Each is kept with its object, its stamp and how far off it was, so it can be told.
  const auto& told = evaluator.total().false_identification_details;
  ASSERT_EQ(told.size(), 2u);
  EXPECT_EQ(told[0].name, "c");
  EXPECT_EQ(told[0].stamp_ns, 1);
  EXPECT_TRUE(std::isnan(told[0].position_error_m));
  EXPECT_EQ(told[1].name, "a");
  EXPECT_NEAR(told[1].position_error_m, 0.2, 1e-9);
  EXPECT_NEAR(told[1].orientation_error_deg, 0.0, 1e-6);
  // Truth frames whose estimates never come are lost once newer ones pile up.
  for (int stamp = 2; stamp <= 5; ++stamp) evaluator.add_truth(stamp, {at("a", 0, 2)});
  EXPECT_EQ(evaluator.total().frames_lost, 2u);
  EXPECT_EQ(evaluator.total().expected, 3u);
  EXPECT_NEAR(evaluator.total().tracked_percent(), 0.0, 1e-12);
  EvaluationSummary window = evaluator.take_window();
  EXPECT_EQ(window.frames, 3u);
  EXPECT_EQ(evaluator.take_window().frames, 0u);
}

// Frames made without a late camera's data are counted apart, in either arrival order, so that
// what the tracking does with complete frames can be told from what a busy machine cost it.
TEST(PoseEvaluator, CountsFramesShortOfACameraApart) {
  PoseEvaluator evaluator;
  evaluator.add_truth(1, {at("a", 0, 2), at("b", 1, 2)});
  evaluator.add_estimate(1, {at("a", 0, 2), at("b", 1, 2)});
  evaluator.add_estimate(2, {at("a", 0, 2)}, /*incomplete=*/true);  // before its truth
  evaluator.add_truth(2, {at("a", 0, 2), at("b", 1, 2)});
  evaluator.add_truth(3, {at("a", 0, 2), at("b", 1, 2)});
  evaluator.add_estimate(3, {at("b", 1, 2)});
  const EvaluationSummary& total = evaluator.total();
  EXPECT_EQ(total.frames, 3u);
  EXPECT_EQ(total.expected, 6u);
  EXPECT_EQ(total.tracked, 4u);
  EXPECT_EQ(total.incomplete_frames, 1u);
  EXPECT_EQ(total.expected_in_incomplete, 2u);
  EXPECT_EQ(total.tracked_in_incomplete, 1u);
  EXPECT_NEAR(total.tracked_percent(), 100.0 * 4 / 6, 1e-12);
  EXPECT_NEAR(total.tracked_percent_in_complete_frames(), 100.0 * 3 / 4, 1e-12);
  EXPECT_EQ(evaluator.take_window().incomplete_frames, 1u);
}

TEST(Overlay, DrawsFiducialsLinesAndAxes) {
  calibration::PinholeIntrinsics k;
  k.fx = k.fy = 500;
  k.cx = 319.5;
  k.cy = 239.5;
  calibration::PinholeCamera camera(640, 480, k);
  cv::Mat image(480, 640, CV_8UC1, cv::Scalar(10));
  overlay::OverlayFrame frame;
  frame.fiducials = {{100, 100}, {std::nan(""), 5}};
  frame.constellations = {{"board", {{"T1", {{{200, 300}, {250, 300}, {300, 300}, {400, 300}}}}}}};
  overlay::OverlayPose pose;
  pose.name = "board";
  pose.camera_from_object.translation() = Eigen::Vector3d(0, 0, 1);
  frame.poses = {pose};
  cv::Mat picture = overlay::draw_overlay(image, frame, &camera, 0.1);
  ASSERT_EQ(picture.type(), CV_8UC3);
  auto pixel = [&](int x, int y) { return picture.at<cv::Vec3b>(y, x); };
  EXPECT_GT(pixel(106, 100)[2], 150);  // yellow circle of radius 6: red and green high
  EXPECT_EQ(pixel(100, 100), cv::Vec3b(10, 10, 10));  // its centre untouched
  EXPECT_GT(pixel(350, 300)[1], 150);                 // green line
  // The x axis of the pose runs from the principal point 50 px to the right, in red.
  EXPECT_GT(pixel(345, 240)[2], 150);
  EXPECT_LT(pixel(345, 240)[0], 100);
  // No camera: no axes, the rest still drawn.
  cv::Mat without = overlay::draw_overlay(image, frame, nullptr);
  EXPECT_EQ(without.at<cv::Vec3b>(240, 345), cv::Vec3b(10, 10, 10));

  // A line with its first marker hidden (NaN) runs between the markers seen, and nothing is
  // drawn towards the image's corner.
  const double hidden = std::nan("");
  frame.constellations = {
      {"board", {{"T1", {{{hidden, hidden}, {250, 400}, {300, 400}, {400, 400}}}}}}};
  cv::Mat broken = overlay::draw_overlay(image, frame, nullptr);
  EXPECT_GT(broken.at<cv::Vec3b>(400, 350)[1], 150);
  EXPECT_EQ(broken.at<cv::Vec3b>(400, 220), cv::Vec3b(10, 10, 10));
  cv::Mat green;
  cv::inRange(broken(cv::Rect(0, 0, 200, 200)), cv::Scalar(0, 150, 0), cv::Scalar(60, 255, 60),
              green);
  EXPECT_EQ(cv::countNonZero(green), 0);
}

// With no frame kept pending, a truth and its estimate could never meet: nothing would be
// evaluated. Options built in code are refused, naming the field.
TEST(EvaluationOptions, NameTheFieldThatCannotBeUsed) {
  using evaluation::EvaluationOptions;
  EXPECT_EQ(EvaluationOptions{}.problem(), std::nullopt);
  EXPECT_EQ(EvaluationOptions{.min_visible_markers = 0}.problem(), std::nullopt);  // any object
  EXPECT_EQ(EvaluationOptions{.min_visible_markers = -1}.problem(),
            "min_visible_markers: -1 is below 0");
  EXPECT_EQ(EvaluationOptions{.false_position_error_m = 0}.problem(),
            "false_position_error_m: 0 is not above 0");
  EXPECT_EQ(EvaluationOptions{.max_pending_frames = 0}.problem(),
            "max_pending_frames: 0; a frame's truth and estimate could never meet");
  try {
    evaluation::PoseEvaluator evaluator({.max_pending_frames = 0});
    ADD_FAILURE() << "no pending frames accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "EvaluationOptions::max_pending_frames: 0; a frame's truth and estimate could never "
              "meet");
  }
}

}  // namespace
}  // namespace mocap
