#include "tracking/body_motion/body_motion.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include <Eigen/Cholesky>

namespace mocap::tracking {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Vector12d = Eigen::Matrix<double, 12, 1>;

// White-noise acceleration of density q over dt: the covariance it adds to (position, velocity)
// along one axis block.
template <class Covariance>
void add_acceleration_noise(Covariance& covariance, int position, int velocity, double q,
                            double dt) {
  const double adt = std::abs(dt);
  const Eigen::Matrix3d identity = Eigen::Matrix3d::Identity();
  covariance.template block<3, 3>(position, position) += q * adt * adt * adt / 3 * identity;
  covariance.template block<3, 3>(position, velocity) += q * dt * adt / 2 * identity;
  covariance.template block<3, 3>(velocity, position) += q * dt * adt / 2 * identity;
  covariance.template block<3, 3>(velocity, velocity) += q * adt * identity;
}

}  // namespace

Eigen::Matrix3d rotation_from_vector(const Eigen::Vector3d& angle_vector) {
  const double angle = angle_vector.norm();
  if (angle < 1e-12) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, angle_vector / angle).toRotationMatrix();
}

Eigen::Vector3d vector_from_rotation(const Eigen::Matrix3d& rotation) {
  const Eigen::AngleAxisd angle_axis(rotation);
  return angle_axis.angle() * angle_axis.axis();
}

std::optional<std::string> BodyMotionOptions::problem() const {
  // A negative density would take uncertainty away: the covariance would stop being one.
  if (!(linear_acceleration_density >= 0)) {
    return fmt::format("linear_acceleration_density: {} is below 0", linear_acceleration_density);
  }
  if (!(angular_acceleration_density >= 0)) {
    return fmt::format("angular_acceleration_density: {} is below 0", angular_acceleration_density);
  }
  if (!(initial_linear_velocity_sigma_mps >= 0)) {
    return fmt::format("initial_linear_velocity_sigma_mps: {} is below 0",
                       initial_linear_velocity_sigma_mps);
  }
  if (!(initial_angular_velocity_sigma_rps >= 0)) {
    return fmt::format("initial_angular_velocity_sigma_rps: {} is below 0",
                       initial_angular_velocity_sigma_rps);
  }
  return std::nullopt;
}

BodyMotionFilter::BodyMotionFilter(const Eigen::Isometry3d& camera_from_body,
                                   const Matrix6d& pose_covariance, int64_t stamp_ns,
                                   BodyMotionOptions options)
    : options_(options) {
  if (auto problem = options_.problem()) {
    throw std::invalid_argument("BodyMotionOptions::" + *problem);
  }
  state_.stamp_ns = stamp_ns;
  state_.camera_from_body = camera_from_body;
  state_.covariance.setZero();
  state_.covariance.topLeftCorner<6, 6>() = pose_covariance;
  const double sv = options_.initial_linear_velocity_sigma_mps;
  const double sw = options_.initial_angular_velocity_sigma_rps;
  state_.covariance.block<3, 3>(6, 6) = sv * sv * Eigen::Matrix3d::Identity();
  state_.covariance.block<3, 3>(9, 9) = sw * sw * Eigen::Matrix3d::Identity();
}

namespace {

// The state's pose `dt` on, `turn` the rotation its angular velocity makes in that time.
Eigen::Isometry3d moved_on(const BodyState& state, double dt, const Eigen::Matrix3d& turn) {
  Eigen::Isometry3d pose = state.camera_from_body;
  pose.translation() += state.linear_velocity * dt;
  pose.linear() = turn * pose.linear();
  return pose;
}

}  // namespace

Eigen::Isometry3d BodyMotionFilter::predicted_pose(int64_t stamp_ns) const {
  const double dt = static_cast<double>(stamp_ns - state_.stamp_ns) * 1e-9;
  if (dt == 0) return state_.camera_from_body;
  return moved_on(state_, dt, rotation_from_vector(state_.angular_velocity * dt));
}

BodyState BodyMotionFilter::predicted(int64_t stamp_ns) const {
  const double dt = static_cast<double>(stamp_ns - state_.stamp_ns) * 1e-9;
  BodyState next = state_;
  next.stamp_ns = stamp_ns;
  if (dt == 0) return next;
  const Eigen::Matrix3d turn = rotation_from_vector(state_.angular_velocity * dt);
  next.camera_from_body = moved_on(state_, dt, turn);
  // F P Fᵀ with F = I but for p += dt v, θ ← turn θ + dt ω, written by its 3-row and 3-column
  // blocks: a swarm predicts each robot every frame, and the full 12 x 12 products cost ten
  // times as much.
  const Matrix12d& p = state_.covariance;
  Matrix12d fp = p;
  fp.middleRows<3>(0) += dt * p.middleRows<3>(6);
  fp.middleRows<3>(3) = turn * p.middleRows<3>(3) + dt * p.middleRows<3>(9);
  next.covariance = fp;
  next.covariance.middleCols<3>(0) += dt * fp.middleCols<3>(6);
  next.covariance.middleCols<3>(3) =
      fp.middleCols<3>(3) * turn.transpose() + dt * fp.middleCols<3>(9);
  add_acceleration_noise(next.covariance, 0, 6, options_.linear_acceleration_density, dt);
  add_acceleration_noise(next.covariance, 3, 9, options_.angular_acceleration_density, dt);
  return next;
}

namespace {

// The measured pose's difference from a predicted one: translation, then rotation vector.
Vector6d innovation_of(const BodyState& prior, const Eigen::Isometry3d& measured) {
  Vector6d residual;
  residual.head<3>() = measured.translation() - prior.camera_from_body.translation();
  residual.tail<3>() =
      vector_from_rotation(measured.linear() * prior.camera_from_body.linear().transpose());
  return residual;
}

}  // namespace

double BodyMotionFilter::surprise(int64_t stamp_ns, const Eigen::Isometry3d& measured,
                                  const Matrix6d& pose_covariance) const {
  const BodyState prior = predicted(stamp_ns);
  const Vector6d residual = innovation_of(prior, measured);
  const Matrix6d innovation = prior.covariance.topLeftCorner<6, 6>() + pose_covariance;
  return residual.dot(innovation.ldlt().solve(residual));
}

double BodyMotionFilter::correct(int64_t stamp_ns, const Eigen::Isometry3d& measured,
                                 const Matrix6d& pose_covariance) {
  BodyState prior = predicted(stamp_ns);
  const Vector6d residual = innovation_of(prior, measured);
  const Matrix6d innovation = prior.covariance.topLeftCorner<6, 6>() + pose_covariance;
  const Eigen::LDLT<Matrix6d> solver(innovation);
  const Eigen::Matrix<double, 12, 6> gain =
      solver.solve(prior.covariance.leftCols<6>().transpose()).transpose();
  const Vector12d delta = gain * residual;

  state_ = prior;
  state_.camera_from_body.translation() += delta.segment<3>(0);
  state_.camera_from_body.linear() =
      rotation_from_vector(delta.segment<3>(3)) * prior.camera_from_body.linear();
  state_.linear_velocity += delta.segment<3>(6);
  state_.angular_velocity += delta.segment<3>(9);
  // Joseph form, (I − K H) P (I − K H)ᵀ + K R Kᵀ: stays symmetric and positive however the gain
  // was rounded. With H = [I 0], (I − K H) P = P − K P's first six rows, and X Hᵀ is X's first
  // six columns.
  const Matrix12d& p = prior.covariance;
  const Matrix12d kept = p - gain * p.topRows<6>();
  const Eigen::Matrix<double, 12, 6> gain_r = gain * pose_covariance;
  state_.covariance = kept - kept.leftCols<6>() * gain.transpose() + gain_r * gain.transpose();
  ++corrections_;
  return residual.dot(solver.solve(residual));
}

PointMotionFilter::PointMotionFilter(const Eigen::Vector3d& position,
                                     const Eigen::Matrix3d& position_covariance, int64_t stamp_ns,
                                     BodyMotionOptions options)
    : options_(options) {
  if (auto problem = options_.problem()) {
    throw std::invalid_argument("BodyMotionOptions::" + *problem);
  }
  state_.stamp_ns = stamp_ns;
  state_.position = position;
  state_.covariance.setZero();
  state_.covariance.topLeftCorner<3, 3>() = position_covariance;
  const double sv = options_.initial_linear_velocity_sigma_mps;
  state_.covariance.bottomRightCorner<3, 3>() = sv * sv * Eigen::Matrix3d::Identity();
}

Eigen::Vector3d PointMotionFilter::predicted_position(int64_t stamp_ns) const {
  const double dt = static_cast<double>(stamp_ns - state_.stamp_ns) * 1e-9;
  return state_.position + state_.velocity * dt;
}

PointState PointMotionFilter::predicted(int64_t stamp_ns) const {
  const double dt = static_cast<double>(stamp_ns - state_.stamp_ns) * 1e-9;
  PointState next = state_;
  next.stamp_ns = stamp_ns;
  if (dt == 0) return next;
  next.position = predicted_position(stamp_ns);
  Matrix6d f = Matrix6d::Identity();
  f.block<3, 3>(0, 3) = dt * Eigen::Matrix3d::Identity();
  next.covariance = f * state_.covariance * f.transpose();
  add_acceleration_noise(next.covariance, 0, 3, options_.linear_acceleration_density, dt);
  return next;
}

double PointMotionFilter::correct(int64_t stamp_ns, const Eigen::Vector3d& measured,
                                  const Eigen::Matrix3d& position_covariance) {
  const PointState prior = predicted(stamp_ns);
  const Eigen::Vector3d residual = measured - prior.position;
  const Eigen::Matrix3d innovation = prior.covariance.topLeftCorner<3, 3>() + position_covariance;
  const Eigen::LDLT<Eigen::Matrix3d> solver(innovation);
  const Eigen::Matrix<double, 6, 3> gain =
      solver.solve(prior.covariance.leftCols<3>().transpose()).transpose();
  const Vector6d delta = gain * residual;
  state_ = prior;
  state_.position += delta.head<3>();
  state_.velocity += delta.tail<3>();
  Matrix6d keep = Matrix6d::Identity();
  keep.leftCols<3>() -= gain;
  state_.covariance =
      keep * prior.covariance * keep.transpose() + gain * position_covariance * gain.transpose();
  return residual.dot(solver.solve(residual));
}

}  // namespace mocap::tracking
