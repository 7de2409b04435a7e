// The four transform value formats of the calibration's files (calibration_config.hpp).
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include <mocap/calibration/calibration_config.hpp>

namespace mocap::calibration {
namespace {

constexpr double kQuaternionNormTolerance = 1e-3;
constexpr double kRotationTolerance = 1e-4;

std::string number_text(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

void require_finite(std::span<const double> values) {
  for (size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      throw std::invalid_argument("number " + std::to_string(i) + " is " + number_text(values[i]));
    }
  }
}

}  // namespace

Eigen::Isometry3d transform_from_values(std::span<const double> values) {
  const size_t n = values.size();
  if (n != 3 && n != 6 && n != 7 && n != 12) {
    throw std::invalid_argument("3, 6, 7 or 12 numbers, not " + std::to_string(n));
  }
  require_finite(values);
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  if (n == 3) {
    transform.translation() = Eigen::Vector3d(values[0], values[1], 0);
    transform.linear() = Eigen::AngleAxisd(values[2], Eigen::Vector3d::UnitZ()).toRotationMatrix();
  } else if (n == 6) {
    transform.translation() = Eigen::Vector3d(values[0], values[1], values[2]);
    const Eigen::Vector3d rotation(values[3], values[4], values[5]);
    const double angle = rotation.norm();
    if (!std::isfinite(angle)) {
      throw std::invalid_argument("the rotation vector's length " + number_text(angle) +
                                  " is not a finite angle");
    }
    if (angle > 0) {
      transform.linear() = Eigen::AngleAxisd(angle, rotation / angle).toRotationMatrix();
    }
  } else if (n == 7) {
    transform.translation() = Eigen::Vector3d(values[0], values[1], values[2]);
    const Eigen::Quaterniond q(values[6], values[3], values[4], values[5]);
    if (std::abs(q.norm() - 1) > kQuaternionNormTolerance) {
      throw std::invalid_argument("the quaternion [qx, qy, qz, qw] has norm " +
                                  number_text(q.norm()) + ", not 1");
    }
    transform.linear() = q.normalized().toRotationMatrix();
  } else {
    Eigen::Matrix3d r;
    r << values[0], values[1], values[2], values[4], values[5], values[6], values[8], values[9],
        values[10];
    const double error = (r.transpose() * r - Eigen::Matrix3d::Identity()).norm();
    // Negated so that NaN (from overflowing products) is refused too.
    if (!(error <= kRotationTolerance) || !(r.determinant() > 0)) {
      throw std::invalid_argument(
          "the 3x3 part is not a rotation (|R'R - I| = " + number_text(error) +
          ", det R = " + number_text(r.determinant()) + ")");
    }
    // Rounded matrices are off by a little; the transform must be exactly rigid.
    transform.linear() = Eigen::Quaterniond(r).normalized().toRotationMatrix();
    transform.translation() = Eigen::Vector3d(values[3], values[7], values[11]);
  }
  return transform;
}

std::vector<double> transform_to_values6(const Eigen::Isometry3d& transform) {
  const Eigen::AngleAxisd rotation(transform.rotation());
  const Eigen::Vector3d vector = rotation.angle() * rotation.axis();
  const Eigen::Vector3d t = transform.translation();
  return {t.x(), t.y(), t.z(), vector.x(), vector.y(), vector.z()};
}

}  // namespace mocap::calibration
