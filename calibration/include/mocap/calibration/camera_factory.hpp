// Camera models by name and flat parameter vector: what the calibration optimises and what
// configuration files name, without the caller knowing each model's class.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <mocap/calibration/camera_model.hpp>

namespace mocap::calibration {

// The camera types and their parameters, in the order of lens_models.hpp:
//   "eucm"     alpha, beta, fu, fv, u0, v0
//   "mei"      xi, k1, k2, k3, k4, k5, fu, fv, u0, v0
//   "pinhole"  fx, fy, cx, cy and optionally k1, k2, p1, p2, k3
//   "ucm"      xi, fu, fv, u0, v0
// "eucm, mei, pinhole, ucm": for messages that list them.
extern const char* const kCameraTypes;

bool is_camera_type(std::string_view type);

// The names of `type`'s parameters in order, as visgeom and camera files spell them ("alpha",
// "beta", ...); empty for an unknown type.
std::span<const std::string_view> camera_parameter_names(std::string_view type);

// Empty when `type` takes `count` parameters; otherwise what it takes, as "eucm takes 6 numbers
// (alpha, beta, fu, fv, u0, v0), not 5". `type` must be a camera type.
std::string camera_parameter_count_problem(std::string_view type, size_t count);

// Throws std::invalid_argument for an unknown type, a wrong number of parameters (with
// camera_parameter_count_problem's text) or values the model rejects.
std::shared_ptr<const CameraModel> make_camera_model(std::string_view type, int width, int height,
                                                     std::span<const double> parameters);

// The inverse of make_camera_model: the model's parameters in the same order (a pinhole always
// gives all nine). Throws std::invalid_argument for a model it does not know.
std::vector<double> camera_parameters(const CameraModel& model);

}  // namespace mocap::calibration
