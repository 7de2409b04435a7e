// Camera models by name and flat parameter vector: what the calibration optimises and what
// configuration files name, without the caller knowing each model's class.
#pragma once

#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include <mocap/calibration/camera_model.hpp>

namespace mocap::calibration {

// "eucm": alpha, beta, fu, fv, u0, v0; "pinhole": fx, fy, cx, cy and optionally k1, k2, p1, p2,
// k3 (the order of lens_models.hpp). Throws std::invalid_argument for an unknown type, a wrong
// number of parameters (naming the type and the count it expects) or values the model rejects.
std::shared_ptr<const CameraModel> make_camera_model(std::string_view type, int width, int height,
                                                     std::span<const double> parameters);

// The inverse of make_camera_model: the model's parameters in the same order (a pinhole always
// gives all nine). Throws std::invalid_argument for a model it does not know.
std::vector<double> camera_parameters(const CameraModel& model);

}  // namespace mocap::calibration
