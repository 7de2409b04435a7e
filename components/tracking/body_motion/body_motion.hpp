// How a tracked body moves between frames: a Kalman filter on SE(3) with a constant-velocity
// model, so that what was known in one frame tells where to look in the next.
//
//   BodyMotionFilter motion(first_pose, first_covariance, stamp_ns);
//   BodyState at_next_frame = motion.predicted(next_stamp_ns);  // where to look for it
//   motion.correct(next_stamp_ns, measured_pose, measured_covariance);
//
// The state is the pose, the linear velocity of the body's origin and the angular velocity,
// all in the frame the poses are measured in (a camera's, or a volume's world: where this file
// says camera_from_body, read the pose in that frame); its error is (δp, δθ, δv, δω) with the
// rotation error a small angle vector applied on the left, R = exp(δθ) R̂, as in
// PlanarPose::covariance. Between frames the
// velocities change by white-noise accelerations of the densities below; a measured pose
// corrects the whole state, so the velocities come out of the track, not of a difference of
// two noisy poses.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace mocap::tracking {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Matrix12d = Eigen::Matrix<double, 12, 12>;

struct BodyMotionOptions {
  // Spectral densities of the white-noise accelerations, m²/s³ and rad²/s³: over a frame of
  // dt seconds the velocity may change by about sqrt(density · dt). A board carried by hand
  // changes its speed by a few m/s within a second; larger values follow faster changes and
  // give noisier velocities.
  double linear_acceleration_density = 2.0;
  double angular_acceleration_density = 8.0;
  // The velocity of a body seen for the first time is unknown: zero, with this standard
  // deviation, until the next frames measure it.
  double initial_linear_velocity_sigma_mps = 2.0;
  double initial_angular_velocity_sigma_rps = 4.0;

  // Why these options cannot be used, naming the field ("linear_acceleration_density: -1 is
  // below 0"); nullopt when they can. BodyMotionFilter's constructor throws
  // std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

// A body's pose and velocities at one instant, with their joint covariance over
// (p, θ, v, ω) (x, y, z each; metres, radians, seconds).
struct BodyState {
  int64_t stamp_ns = 0;
  Eigen::Isometry3d camera_from_body = Eigen::Isometry3d::Identity();
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();   // of the body's origin, m/s
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // rad/s
  Matrix12d covariance = Matrix12d::Identity();

  Matrix6d pose_covariance() const { return covariance.topLeftCorner<6, 6>(); }
  Matrix6d velocity_covariance() const { return covariance.bottomRightCorner<6, 6>(); }
};

class BodyMotionFilter {
 public:
  // Starts a track at a measured pose whose covariance is `pose_covariance` (6x6 over p, θ).
  BodyMotionFilter(const Eigen::Isometry3d& camera_from_body, const Matrix6d& pose_covariance,
                   int64_t stamp_ns, BodyMotionOptions options = {});

  // The state carried forward (or back) to `stamp_ns` by the constant-velocity model.
  BodyState predicted(int64_t stamp_ns) const;
  // Its pose alone, without the covariance's 12 x 12 products: where to look for the body.
  Eigen::Isometry3d predicted_pose(int64_t stamp_ns) const;

  // Moves the state to `stamp_ns` and corrects it with a measured pose of covariance
  // `pose_covariance`. Returns the squared Mahalanobis distance of the measurement from the
  // prediction (6 degrees of freedom): how surprising it was.
  double correct(int64_t stamp_ns, const Eigen::Isometry3d& measured,
                 const Matrix6d& pose_covariance);

  // The squared Mahalanobis distance of a measured pose from the prediction at `stamp_ns` (6
  // degrees of freedom), without correcting anything: a gate on jumps no motion explains.
  double surprise(int64_t stamp_ns, const Eigen::Isometry3d& measured,
                  const Matrix6d& pose_covariance) const;

  const BodyState& state() const { return state_; }
  // Frames corrected so far, the first included.
  int corrections() const { return corrections_; }

 private:
  BodyMotionOptions options_;
  BodyState state_;
  int corrections_ = 1;
};

// A point's position and velocity at one instant, with their joint covariance over (p, v).
struct PointState {
  int64_t stamp_ns = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Matrix6d covariance = Matrix6d::Identity();
};

// The same constant-velocity model for a point that has no orientation (a robot of one marker):
// BodyMotionFilter's linear half, with its linear density and initial velocity sigma.
class PointMotionFilter {
 public:
  PointMotionFilter(const Eigen::Vector3d& position, const Eigen::Matrix3d& position_covariance,
                    int64_t stamp_ns, BodyMotionOptions options = {});

  PointState predicted(int64_t stamp_ns) const;
  // Its position alone.
  Eigen::Vector3d predicted_position(int64_t stamp_ns) const;
  // As BodyMotionFilter::correct, over 3 degrees of freedom.
  double correct(int64_t stamp_ns, const Eigen::Vector3d& measured,
                 const Eigen::Matrix3d& position_covariance);

  const PointState& state() const { return state_; }

 private:
  BodyMotionOptions options_;
  PointState state_;
};

// exp and log of rotations as angle vectors (radians).
Eigen::Matrix3d rotation_from_vector(const Eigen::Vector3d& angle_vector);
Eigen::Vector3d vector_from_rotation(const Eigen::Matrix3d& rotation);

}  // namespace mocap::tracking
