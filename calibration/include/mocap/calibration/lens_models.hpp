// Lens models as templated free functions, so that one formula serves the camera classes
// (T = double) and the calibration's cost functions (T = ceres::Jet, automatic derivatives).
// Only arithmetic, comparisons and sqrt (found by argument-dependent lookup for Jets) are used,
// so this header needs neither Ceres nor anything else.
//
// Camera frame: x right, y down, z forward; pixels: u right, v down (camera_model.hpp).
#pragma once

#include <cmath>

namespace mocap::calibration {

// Enhanced Unified Camera Model (Khomutenko, Garcia, Martinet, "An Enhanced Unified Camera
// Model", IEEE Robotics and Automation Letters 1(1), 2016): alpha, beta, fu, fv, u0, v0.
constexpr int kEucmParameters = 6;

// Pinhole with OpenCV's radial-tangential distortion ("plumb_bob"): fx, fy, cx, cy, k1, k2, p1,
// p2, k3.
constexpr int kPinholeParameters = 9;

// OpenCV's radial-tangential distortion of normalised coordinates (x/z, y/z); `distortion` is
// k1, k2, p1, p2, k3.
template <class T>
void pinhole_distort(const T* distortion, const T* normalised, T* distorted) {
  const T& k1 = distortion[0];
  const T& k2 = distortion[1];
  const T& p1 = distortion[2];
  const T& p2 = distortion[3];
  const T& k3 = distortion[4];
  const T& x = normalised[0];
  const T& y = normalised[1];
  T r2 = x * x + y * y;
  T radial = T(1) + r2 * (k1 + r2 * (k2 + r2 * k3));
  distorted[0] = x * radial + T(2) * p1 * x * y + p2 * (r2 + T(2) * x * x);
  distorted[1] = y * radial + p1 * (r2 + T(2) * y * y) + T(2) * p2 * x * y;
}

// u = fx·x' + cx, v = fy·y' + cy with (x', y') the distorted (x/z, y/z). False, leaving `pixel`
// untouched, for z <= 0: the pinhole images only what is in front of it.
template <class T>
bool pinhole_project(const T* parameters, const T* point, T* pixel) {
  if (!(point[2] > T(0))) return false;
  const T normalised[2] = {point[0] / point[2], point[1] / point[2]};
  T distorted[2];
  pinhole_distort(parameters + 4, normalised, distorted);
  pixel[0] = parameters[0] * distorted[0] + parameters[2];
  pixel[1] = parameters[1] * distorted[1] + parameters[3];
  return true;
}

// EUCM, as in the paper:
//   rho = sqrt(z² + beta·(x² + y²)),  d = alpha·rho + (1 − alpha)·z,
//   u = fu·x/d + u0,  v = fv·y/d + v0.
// alpha in [0, 1] blends a pinhole (alpha = 0, where beta plays no part) with a projection
// through an ellipsoid of revolution whose shape is beta (beta = 1: a sphere, the Unified
// Camera Model). The point is first projected onto the ellipsoid; the map from points to pixels
// is one-to-one only on the side of the ellipsoid facing the image, which is the paper's
// validity condition
//   z > −w·rho,  w = alpha / (1 − alpha) for alpha <= 0.5, (1 − alpha) / alpha for alpha > 0.5,
// plus d > 0 (implied by the former, kept so that no division by zero can happen). For
// alpha <= 0.5 the condition is d > 0 itself; for alpha > 0.5 it is stricter. Either way
// points a little behind the camera (z < 0) can be valid: wide lenses see beyond 90 degrees.
// Returns false, leaving `pixel` untouched, outside that region.
template <class T>
bool eucm_project(const T* parameters, const T* point, T* pixel) {
  using std::sqrt;
  const T& alpha = parameters[0];
  const T& beta = parameters[1];
  const T& x = point[0];
  const T& y = point[1];
  const T& z = point[2];
  T rho = sqrt(z * z + beta * (x * x + y * y));
  T d = alpha * rho + (T(1) - alpha) * z;
  T w = alpha > T(0.5) ? (T(1) - alpha) / alpha : alpha / (T(1) - alpha);
  if (!(z > -w * rho) || !(d > T(0))) return false;
  pixel[0] = parameters[2] * x / d + parameters[4];
  pixel[1] = parameters[3] * y / d + parameters[5];
  return true;
}

}  // namespace mocap::calibration
