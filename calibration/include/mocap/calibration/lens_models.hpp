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

// The Unified Camera Model (Geyer and Daniilidis; Barreto), as visgeom writes it: xi, fu, fv,
// u0, v0.
constexpr int kUcmParameters = 5;

// The unified model with radial-tangential distortion of its normalised plane (Mei and Rives,
// "Single View Point Omnidirectional Camera Calibration from Planar Grids", ICRA 2007), as
// visgeom writes it: xi, k1, k2, k3, k4, k5, fu, fv, u0, v0, where k1-k3 are radial and k4, k5
// tangential (OpenCV's p1, p2).
constexpr int kMeiParameters = 10;

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

// The unified model's projection onto its normalised plane: the point is moved onto the unit
// sphere and projected from (0, 0, −xi) onto the plane z = 1,
//   rho = |p|,  (xn, yn) = (x, y) / (z + xi·rho).
// It equals EUCM with beta = 1 and alpha = xi / (1 + xi), scaled by 1 + xi, and has EUCM's
// validity condition z > −w·rho with w = xi for xi <= 1 and 1 / xi beyond. Returns false,
// leaving `normalised` untouched, outside it.
template <class T>
bool unified_normalise(const T& xi, const T* point, T* normalised) {
  using std::sqrt;
  const T& x = point[0];
  const T& y = point[1];
  const T& z = point[2];
  T rho = sqrt(x * x + y * y + z * z);
  T denominator = z + xi * rho;
  T w = xi > T(1) ? T(1) / xi : xi;
  if (!(z > -w * rho) || !(denominator > T(0))) return false;
  normalised[0] = x / denominator;
  normalised[1] = y / denominator;
  return true;
}

// UCM: u = fu·xn + u0, v = fv·yn + v0 (unified_normalise).
template <class T>
bool ucm_project(const T* parameters, const T* point, T* pixel) {
  T normalised[2];
  if (!unified_normalise(parameters[0], point, normalised)) return false;
  pixel[0] = parameters[1] * normalised[0] + parameters[3];
  pixel[1] = parameters[2] * normalised[1] + parameters[4];
  return true;
}

// Mei: the UCM with its normalised plane distorted as OpenCV distorts a pinhole's.
template <class T>
bool mei_project(const T* parameters, const T* point, T* pixel) {
  T normalised[2];
  if (!unified_normalise(parameters[0], point, normalised)) return false;
  const T distortion[5] = {parameters[1], parameters[2], parameters[4], parameters[5],
                           parameters[3]};  // pinhole_distort's order: k1, k2, p1, p2, k3
  T distorted[2];
  pinhole_distort(distortion, normalised, distorted);
  pixel[0] = parameters[6] * distorted[0] + parameters[8];
  pixel[1] = parameters[7] * distorted[1] + parameters[9];
  return true;
}

// The inverse of pinhole_distort by Newton's method: the normalised point that `distortion`
// (k1, k2, p1, p2, k3) moves to `distorted`. False where it does not converge (outside the
// region where the distortion is one-to-one).
inline bool pinhole_undistort(const double* distortion, const double* distorted,
                              double* normalised) {
  double p[2] = {distorted[0], distorted[1]};
  auto residual = [&](const double* at, double* r) {
    pinhole_distort(distortion, at, r);
    r[0] -= distorted[0];
    r[1] -= distorted[1];
  };
  double r[2];
  for (int iteration = 0; iteration < 20; ++iteration) {
    residual(p, r);
    if (r[0] * r[0] + r[1] * r[1] < 1e-24) break;
    // A numeric Jacobian, inverted as the 2x2 matrix it is.
    constexpr double h = 1e-7;
    const double px[2] = {p[0] + h, p[1]}, py[2] = {p[0], p[1] + h};
    double rx[2], ry[2];
    residual(px, rx);
    residual(py, ry);
    const double a = (rx[0] - r[0]) / h, b = (ry[0] - r[0]) / h;
    const double c = (rx[1] - r[1]) / h, d = (ry[1] - r[1]) / h;
    const double determinant = a * d - b * c;
    if (!(std::abs(determinant) > 1e-300)) return false;
    p[0] -= (d * r[0] - b * r[1]) / determinant;
    p[1] -= (a * r[1] - c * r[0]) / determinant;
    if (!std::isfinite(p[0]) || !std::isfinite(p[1])) return false;
  }
  residual(p, r);
  if (!(std::sqrt(r[0] * r[0] + r[1] * r[1]) <= 1e-9)) return false;
  normalised[0] = p[0];
  normalised[1] = p[1];
  return true;
}

}  // namespace mocap::calibration
