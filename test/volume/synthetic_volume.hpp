// A synthetic volume for the fusion's tests and benchmark: four pinhole cameras 2.5 m up at the
// corners of a 4 x 4 m floor, a planar board of eight markers, its views with pixel noise.
#pragma once

#include <memory>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include <mocap/calibration/camera_factory.hpp>

#include "volume/pose_fusion/pose_fusion.hpp"

namespace mocap::volume::test {

// N draws of `distribution`, in order: draws written as the arguments of one call happen in an
// order the compiler chooses, which would make a test's numbers depend on the build.
template <int N, class Distribution>
Eigen::Matrix<double, N, 1> draws(Distribution& distribution, std::mt19937& random) {
  Eigen::Matrix<double, N, 1> values;
  for (int i = 0; i < N; ++i) values[i] = distribution(random);
  return values;
}

inline constexpr double kPi = 3.14159265358979323846;

// A camera at `position` looking at `target`, image x roughly along the world's horizontal.
inline Eigen::Isometry3d camera_from_world_looking(const Eigen::Vector3d& position,
                                                   const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - position).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d world_from_camera = Eigen::Isometry3d::Identity();
  world_from_camera.linear() << x, y, z;
  world_from_camera.translation() = position;
  return world_from_camera.inverse();
}

// Four cameras 2.5 m up at the corners of a 4 x 4 m floor, looking at its centre 1 m up.
struct Volume {
  Volume() {
    const std::vector<double> intrinsics = {900, 900, 639.5, 359.5};  // fx, fy, cx, cy
    camera = calibration::make_camera_model("pinhole", 1280, 720, intrinsics);
    for (double x : {-2.0, 2.0}) {
      for (double y : {-2.0, 2.0}) {
        extrinsics.push_back(camera_from_world_looking({x, y, 2.5}, Eigen::Vector3d(0, 0, 1)));
      }
    }
  }
  std::shared_ptr<const calibration::CameraModel> camera;
  std::vector<Eigen::Isometry3d> extrinsics;
};

// A planar board of eight markers, 30 x 20 cm, none symmetric to another.
inline const std::vector<Eigen::Vector3d> kBoard = {
    {0, 0, 0},       {0.10, 0, 0},    {0.30, 0, 0}, {0.30, 0.08, 0},
    {0.30, 0.20, 0}, {0.12, 0.20, 0}, {0, 0.20, 0}, {0, 0.13, 0}};

// Each camera's view of the board at `world_from_body`, with Gaussian pixel noise; a camera
// that does not see every marker in its image sees nothing.
inline std::vector<CameraView> views_of(const Volume& volume,
                                        const Eigen::Isometry3d& world_from_body, double noise_px,
                                        std::mt19937& random) {
  std::normal_distribution<double> noise(0, noise_px);
  std::vector<CameraView> views;
  for (const Eigen::Isometry3d& extrinsic : volume.extrinsics) {
    CameraView view{volume.camera.get(), extrinsic, {}, {}, {}};
    for (const Eigen::Vector3d& point : kBoard) {
      auto pixel = volume.camera->project(extrinsic * world_from_body * point);
      if (!pixel || !volume.camera->in_image(*pixel)) {
        view.body_points.clear();
        view.pixels.clear();
        break;
      }
      view.body_points.push_back(point);
      view.pixels.push_back(*pixel + draws<2>(noise, random));
    }
    views.push_back(std::move(view));
  }
  return views;
}

// A board pose in the volume, facing up within 40 degrees, any yaw.
inline Eigen::Isometry3d random_pose(std::mt19937& random) {
  std::uniform_real_distribution<double> across(-1.0, 1.0), height(0.3, 1.5), tilt(-0.7, 0.7),
      yaw(-kPi, kPi);
  const double heading = yaw(random), roll = tilt(random), pitch = tilt(random);
  const double x = across(random), y = across(random), z = height(random);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = (Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()) *
                   Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()))
                      .toRotationMatrix();
  pose.translation() = Eigen::Vector3d(x, y, z);
  return pose;
}

}  // namespace mocap::volume::test
