// The plane's two poses in closed form (components/tracking/pose_estimator/ippe.hpp), against
// the truth and against OpenCV's IPPE (cv::solvePnPGeneric, SOLVEPNP_IPPE), which the planar
// pose estimator used before: the same two poses from exact rays, and poses as good from noisy
// ones.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <opencv2/calib3d.hpp>

#include "tracking/pose_estimator/ippe.hpp"

namespace mocap::pose {
namespace {

double angle_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() * 180 / std::numbers::pi;
}

struct View {
  Eigen::Isometry3d truth;
  std::vector<Eigen::Vector2d> plane, rays;
};

// Eight points of a 30 x 20 cm board (centred on their mean) at 0.5 to 4 m, turned up to 60
// degrees from facing the camera, seen at normalised rays with `noise` (radians) added.
View random_view(std::mt19937& random, double noise) {
  std::uniform_real_distribution<double> unit(-1, 1), distance(0.5, 4);
  std::normal_distribution<double> jitter(0, noise);
  // One draw per statement: the arguments of one call are evaluated in an order the compiler
  // chooses, which would make the views depend on the build.
  auto pair = [&](auto& distribution, double sx, double sy) {
    const double x = sx * distribution(random);
    return Eigen::Vector2d(x, sy * distribution(random));
  };
  View view;
  for (int i = 0; i < 8; ++i) view.plane.push_back(pair(unit, 0.15, 0.1));
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : view.plane) mean += p;
  for (auto& p : view.plane) p -= mean / 8.0;
  const Eigen::Vector2d tilt_axis = pair(unit, 1, 1);
  const double turn = std::numbers::pi * unit(random);
  const double tilt = 1.05 * std::abs(unit(random));
  view.truth = Eigen::Isometry3d::Identity();
  view.truth.linear() =
      (Eigen::AngleAxisd(turn, Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd(tilt, Eigen::Vector3d(tilt_axis.x(), tilt_axis.y(), 0).normalized()))
          .toRotationMatrix();
  const double depth = distance(random);
  const Eigen::Vector2d across = pair(unit, 0.3 * depth, 0.2 * depth);
  view.truth.translation() = Eigen::Vector3d(across.x(), across.y(), depth);
  for (const auto& p : view.plane) {
    const Eigen::Vector3d seen = view.truth * Eigen::Vector3d(p.x(), p.y(), 0);
    view.rays.push_back(seen.head<2>() / seen.z() + pair(jitter, 1, 1));
  }
  return view;
}

std::vector<Eigen::Isometry3d> opencv_poses(const View& view) {
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (size_t i = 0; i < view.plane.size(); ++i) {
    object.emplace_back(view.plane[i].x(), view.plane[i].y(), 0);
    image.emplace_back(view.rays[i].x(), view.rays[i].y());
  }
  std::vector<cv::Mat> rotations, translations;
  cv::solvePnPGeneric(object, image, cv::Mat::eye(3, 3, CV_64F), cv::Mat(), rotations, translations,
                      false, cv::SOLVEPNP_IPPE);
  std::vector<Eigen::Isometry3d> poses;
  for (size_t s = 0; s < rotations.size(); ++s) {
    cv::Mat r;
    cv::Rodrigues(rotations[s], r);
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) pose.linear()(i, j) = r.at<double>(i, j);
      pose.translation()(i) = translations[s].at<double>(i);
    }
    poses.push_back(pose);
  }
  return poses;
}

// RMS distance between the rays and where `pose` images the plane's points.
double ray_rms(const View& view, const Eigen::Isometry3d& pose) {
  double sum = 0;
  for (size_t i = 0; i < view.plane.size(); ++i) {
    const Eigen::Vector3d seen = pose * Eigen::Vector3d(view.plane[i].x(), view.plane[i].y(), 0);
    sum += (seen.head<2>() / seen.z() - view.rays[i]).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(view.plane.size()));
}

TEST(PlanePoses, ExactRaysGiveTheTruthAndOpenCvsOtherPose) {
  std::mt19937 random(11);
  for (int trial = 0; trial < 200; ++trial) {
    const View view = random_view(random, 0);
    const auto ours = plane_poses(view.plane, view.rays);
    ASSERT_TRUE(ours) << "trial " << trial;
    const auto theirs = opencv_poses(view);
    ASSERT_EQ(theirs.size(), 2u);
    // One of ours is the truth; each of ours is one of OpenCV's.
    double nearest_truth = 1e9;
    for (const Eigen::Isometry3d& pose : *ours) {
      nearest_truth =
          std::min(nearest_truth, angle_deg(pose.linear(), view.truth.linear()) +
                                      (pose.translation() - view.truth.translation()).norm());
      double nearest_opencv = 1e9;
      for (const Eigen::Isometry3d& other : theirs) {
        nearest_opencv =
            std::min(nearest_opencv, angle_deg(pose.linear(), other.linear()) +
                                         (pose.translation() - other.translation()).norm());
      }
      EXPECT_LT(nearest_opencv, 1e-6) << "trial " << trial;
    }
    EXPECT_LT(nearest_truth, 1e-7) << "trial " << trial;
  }
}

// With a third of a pixel of noise at a 900 px focal length, the better of our two poses
// images the points as well as the better of OpenCV's (the homographies are fitted by different
// least squares, so the poses differ by the noise's share).
TEST(PlanePoses, NoisyRaysGivePosesAsGoodAsOpenCvs) {
  std::mt19937 random(12);
  double ours_total = 0, theirs_total = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const View view = random_view(random, 0.33 / 900);
    const auto ours = plane_poses(view.plane, view.rays);
    ASSERT_TRUE(ours) << "trial " << trial;
    const auto theirs = opencv_poses(view);
    const double ours_best = std::min(ray_rms(view, (*ours)[0]), ray_rms(view, (*ours)[1]));
    const double theirs_best = std::min(ray_rms(view, theirs[0]), ray_rms(view, theirs[1]));
    EXPECT_LT(ours_best, 1.5 * theirs_best + 1e-6) << "trial " << trial;
    ours_total += ours_best;
    theirs_total += theirs_best;
  }
  EXPECT_LT(ours_total, 1.05 * theirs_total);
  RecordProperty("mean_rms_px_ours", std::to_string(ours_total / 200 * 900));
  RecordProperty("mean_rms_px_opencv", std::to_string(theirs_total / 200 * 900));
}

TEST(PlanePoses, TooFewOrCollinearPointsGiveNone) {
  const std::vector<Eigen::Vector2d> three = {{0, 0}, {0.1, 0}, {0, 0.1}};
  EXPECT_FALSE(plane_poses(three, three));
  const std::vector<Eigen::Vector2d> line = {{-0.2, 0}, {-0.1, 0}, {0.1, 0}, {0.2, 0}};
  const std::vector<Eigen::Vector2d> rays = {{-0.1, 0}, {-0.05, 0}, {0.05, 0}, {0.1, 0}};
  EXPECT_FALSE(plane_poses(line, rays));
}

}  // namespace
}  // namespace mocap::pose
