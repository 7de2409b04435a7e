#include <mocap/calibration/camera_factory.hpp>

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>

#include <mocap/calibration/eucm_camera.hpp>
#include <mocap/calibration/lens_models.hpp>
#include <mocap/calibration/pinhole_camera.hpp>

namespace mocap::calibration {

std::shared_ptr<const CameraModel> make_camera_model(std::string_view type, int width, int height,
                                                     std::span<const double> parameters) {
  if (type == "eucm") {
    if (parameters.size() != kEucmParameters) {
      throw std::invalid_argument(
          "camera model 'eucm' needs 6 parameters (alpha, beta, fu, fv, "
          "u0, v0), got " +
          std::to_string(parameters.size()));
    }
    std::array<double, kEucmParameters> values;
    std::copy(parameters.begin(), parameters.end(), values.begin());
    return std::make_shared<EucmCamera>(width, height, values);
  }
  if (type == "pinhole") {
    if (parameters.size() != 4 && parameters.size() != kPinholeParameters) {
      throw std::invalid_argument(
          "camera model 'pinhole' needs 4 parameters (fx, fy, cx, cy) or "
          "9 (with k1, k2, p1, p2, k3), got " +
          std::to_string(parameters.size()));
    }
    PinholeIntrinsics intrinsics{parameters[0], parameters[1], parameters[2], parameters[3]};
    for (size_t i = 4; i < parameters.size(); ++i) intrinsics.distortion[i - 4] = parameters[i];
    return std::make_shared<PinholeCamera>(width, height, intrinsics);
  }
  throw std::invalid_argument("unknown camera model '" + std::string(type) +
                              "' (known: eucm, pinhole)");
}

std::vector<double> camera_parameters(const CameraModel& model) {
  if (const auto* eucm = dynamic_cast<const EucmCamera*>(&model)) {
    return {eucm->parameters().begin(), eucm->parameters().end()};
  }
  if (const auto* pinhole = dynamic_cast<const PinholeCamera*>(&model)) {
    return {pinhole->parameters().begin(), pinhole->parameters().end()};
  }
  throw std::invalid_argument("camera model '" + model.type() + "' has no parameter vector");
}

}  // namespace mocap::calibration
