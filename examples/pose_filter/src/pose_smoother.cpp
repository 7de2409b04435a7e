#include "pose_smoother.hpp"

namespace pose_filter {

SmoothedPose PoseSmoother::update(const std::string& name, double time_s,
                                  const Eigen::Isometry3d& pose) {
  const Eigen::Vector3d position = pose.translation();
  Eigen::Quaterniond orientation(pose.rotation());
  auto [it, inserted] = tracks_.try_emplace(name);
  Track& track = it->second;
  const bool restart = inserted || time_s - track.last_time_s > options_.restart_after_s ||
                       time_s < track.last_time_s;
  if (restart) {
    track.position = position;
    track.orientation = orientation;
    track.samples = 0;
  } else {
    track.position += options_.position_smoothing * (position - track.position);
    // q and -q are one rotation: blend towards the nearer one.
    if (track.orientation.dot(orientation) < 0) orientation.coeffs() *= -1;
    track.orientation = track.orientation.slerp(options_.orientation_smoothing, orientation);
  }
  track.last_time_s = time_s;
  ++track.samples;

  SmoothedPose out;
  out.pose = Eigen::Isometry3d::Identity();
  out.pose.translate(track.position);
  out.pose.rotate(track.orientation.normalized());
  out.samples = track.samples;
  out.restarted = restart;
  return out;
}

}  // namespace pose_filter
