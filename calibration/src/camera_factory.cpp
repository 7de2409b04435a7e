#include <mocap/calibration/camera_factory.hpp>

#include <algorithm>
#include <array>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <mocap/calibration/eucm_camera.hpp>
#include <mocap/calibration/lens_models.hpp>
#include <mocap/calibration/pinhole_camera.hpp>
#include <mocap/calibration/unified_camera.hpp>

namespace mocap::calibration {
namespace {

struct CameraType {
  std::string_view name;
  std::vector<std::string_view> parameters;  // the full form's, in order
  size_t short_count;                        // a shorter form (0: none), the first parameters
};

const std::array<CameraType, 4> kTypes = {{
    {"eucm", {"alpha", "beta", "fu", "fv", "u0", "v0"}, 0},
    {"mei", {"xi", "k1", "k2", "k3", "k4", "k5", "fu", "fv", "u0", "v0"}, 0},
    {"pinhole", {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"}, 4},
    {"ucm", {"xi", "fu", "fv", "u0", "v0"}, 0},
}};

const CameraType* find_type(std::string_view name) {
  for (const CameraType& type : kTypes) {
    if (type.name == name) return &type;
  }
  return nullptr;
}

}  // namespace

const char* const kCameraTypes = "eucm, mei, pinhole, ucm";

bool is_camera_type(std::string_view type) { return find_type(type) != nullptr; }

std::span<const std::string_view> camera_parameter_names(std::string_view name) {
  const CameraType* type = find_type(name);
  if (!type) return {};
  return type->parameters;
}

std::string camera_parameter_count_problem(std::string_view name, size_t count) {
  const CameraType* type = find_type(name);
  if (!type) return fmt::format("unknown camera type '{}' ({})", name, kCameraTypes);
  const size_t full = type->parameters.size(), short_count = type->short_count;
  if (count == full || (short_count > 0 && count == short_count)) return "";
  const auto names = [&](size_t from, size_t to) {
    return fmt::format("{}", fmt::join(type->parameters.begin() + static_cast<long>(from),
                                       type->parameters.begin() + static_cast<long>(to), ", "));
  };
  if (short_count > 0) {
    return fmt::format("{} takes {} or {} numbers ({}, then {}), not {}", name, short_count, full,
                       names(0, short_count), names(short_count, full), count);
  }
  return fmt::format("{} takes {} numbers ({}), not {}", name, full, names(0, full), count);
}

std::shared_ptr<const CameraModel> make_camera_model(std::string_view type, int width, int height,
                                                     std::span<const double> parameters) {
  if (const std::string problem = camera_parameter_count_problem(type, parameters.size());
      !problem.empty()) {
    throw std::invalid_argument(problem);
  }
  if (type == "eucm") {
    std::array<double, kEucmParameters> values;
    std::copy(parameters.begin(), parameters.end(), values.begin());
    return std::make_shared<EucmCamera>(width, height, values);
  }
  if (type == "pinhole") {
    PinholeIntrinsics intrinsics{parameters[0], parameters[1], parameters[2], parameters[3]};
    for (size_t i = 4; i < parameters.size(); ++i) intrinsics.distortion[i - 4] = parameters[i];
    return std::make_shared<PinholeCamera>(width, height, intrinsics);
  }
  return std::make_shared<UnifiedCamera>(width, height, parameters);  // ucm or mei
}

std::vector<double> camera_parameters(const CameraModel& model) {
  if (const auto* eucm = dynamic_cast<const EucmCamera*>(&model)) {
    return {eucm->parameters().begin(), eucm->parameters().end()};
  }
  if (const auto* pinhole = dynamic_cast<const PinholeCamera*>(&model)) {
    return {pinhole->parameters().begin(), pinhole->parameters().end()};
  }
  if (const auto* unified = dynamic_cast<const UnifiedCamera*>(&model)) {
    return unified->parameters();
  }
  throw std::invalid_argument("camera model '" + model.type() + "' has no parameter vector");
}

}  // namespace mocap::calibration
