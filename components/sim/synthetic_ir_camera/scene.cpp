#include "sim/synthetic_ir_camera/scene.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <set>
#include <sstream>
#include <string_view>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "common/yaml_reader/yaml_reader.hpp"

namespace mocap::synthetic {
namespace {

using Keys = YamlKeys;

// Reads one scene document; every error names the source and the line of the node at fault.
class SceneReader : YamlReader<SceneError> {
 public:
  SceneReader(std::string source, const constellations::ConstellationDatabase& database)
      : YamlReader(std::move(source)), database_(database) {}

  Scene read(const YAML::Node& root) {
    if (!root.IsMap()) {
      fail(root,
           "a scene is a map with 'objects' (and optionally 'render', 'distractors', 'seed')");
    }
    check_keys(root, {"objects", "render", "distractors", "seed"}, "the scene");
    Scene scene;
    scene.source = source();
    scene.seed =
        static_cast<uint64_t>(integer(root, "seed", 1, 0, std::numeric_limits<int64_t>::max()));
    if (YAML::Node render = root["render"]) scene.render = render_options(render);
    if (YAML::Node distractors = root["distractors"]) {
      scene.distractors = read_distractors(distractors);
    }
    YAML::Node objects = required(root, "objects", "the scene");
    if (!objects.IsSequence()) {
      fail(objects, "'objects' must be a list of {constellation, trajectory}");
    }
    for (const YAML::Node& object : objects) scene.objects.push_back(scene_object(object));
    return scene;
  }

 private:
  RenderOptions render_options(const YAML::Node& map) const {
    check_keys(map,
               {"marker_diameter_m", "exposure", "background_dn", "noise_sigma_dn", "blur_sigma_px",
                "motion_blur_s", "motion_blur_steps", "supersampling"},
               "'render'");
    RenderOptions options;
    options.marker_diameter_m = positive(map, "marker_diameter_m", options.marker_diameter_m, 1);
    options.exposure = number(map, "exposure", options.exposure, 0, 100);
    options.background_dn = number(map, "background_dn", options.background_dn, 0, 255);
    options.noise_sigma_dn = number(map, "noise_sigma_dn", options.noise_sigma_dn, 0, 100);
    options.blur_sigma_px = number(map, "blur_sigma_px", options.blur_sigma_px, 0, 20);
    options.motion_blur_s = number(map, "motion_blur_s", options.motion_blur_s, 0, 10);
    options.motion_blur_steps =
        static_cast<int>(integer(map, "motion_blur_steps", options.motion_blur_steps, 0, 256));
    options.supersampling =
        static_cast<int>(integer(map, "supersampling", options.supersampling, 1, 16));
    return options;
  }

  SceneObject scene_object(const YAML::Node& map) const {
    check_keys(map, {"constellation", "trajectory", "occlusion"}, "an object");
    SceneObject object;
    YAML::Node name = required(map, "constellation", "an object");
    if (!name.IsScalar()) fail(name, "'constellation' must be a name");
    const constellations::ConstellationModel* model = database_.find(name.Scalar());
    if (model == nullptr) {
      std::vector<std::string> known;
      for (const auto& constellation : database_.constellations())
        known.push_back(constellation.name);
      fail(name, fmt::format("unknown constellation '{}' (known: {})", name.Scalar(),
                             known.empty() ? "none" : fmt::format("{}", fmt::join(known, ", "))));
    }
    object.constellation = model->name;
    object.markers = model->points;
    object.trajectory = trajectory(required(map, "trajectory", "an object"));
    if (YAML::Node occlusion = map["occlusion"]) {
      check_keys(occlusion, {"fraction", "side", "max_fraction", "period_s"}, "'occlusion'");
      ObjectOcclusion value;
      value.fraction = to_number(required(occlusion, "fraction", "'occlusion'"), "fraction", 0, 1);
      value.max_fraction = number(occlusion, "max_fraction", value.fraction, 0, 1);
      value.period_s = number(occlusion, "period_s", 0, 0, 1e6);
      value.side = static_cast<ObjectOcclusion::Side>(
          choice(occlusion, "side", {"left", "right", "top", "bottom"}, 0));
      object.occlusion = value;
    }
    return object;
  }

  Trajectory trajectory(const YAML::Node& map) const {
    if (!map.IsMap()) fail(map, "'trajectory' must be a map with a 'type'");
    required(map, "type", "'trajectory'");
    size_t index = choice(map, "type", {"static", "keyframes", "orbit", "walk", "spin"}, 0);
    constexpr double kFar = 1e6;  // metres, seconds, degrees: beyond any sensible scene
    switch (index) {
      case 0: {
        check_keys(map, {"type", "position", "rpy_deg"}, "a static trajectory");
        StaticTrajectory motion;
        motion.position = vector<3>(required(map, "position", "a static trajectory"), "position");
        motion.rpy_deg = vector<3>(map, "rpy_deg", motion.rpy_deg);
        return motion;
      }
      case 1: {
        check_keys(map, {"type", "keyframes", "loop"}, "a keyframes trajectory");
        KeyframeTrajectory motion;
        motion.loop = boolean(map, "loop", false);
        YAML::Node keys = required(map, "keyframes", "a keyframes trajectory");
        if (!keys.IsSequence() || keys.size() == 0) {
          fail(keys, "'keyframes' must be a list of {t, position, rpy_deg}");
        }
        for (const YAML::Node& key : keys) {
          check_keys(key, {"t", "position", "rpy_deg"}, "a keyframe");
          Keyframe keyframe;
          keyframe.time_s = to_number(required(key, "t", "a keyframe"), "t", -kFar, kFar);
          keyframe.position = vector<3>(required(key, "position", "a keyframe"), "position");
          keyframe.rpy_deg = vector<3>(key, "rpy_deg", keyframe.rpy_deg);
          if (!motion.keyframes.empty() && keyframe.time_s <= motion.keyframes.back().time_s) {
            fail(key["t"], fmt::format("keyframe times must increase: {} follows {}",
                                       keyframe.time_s, motion.keyframes.back().time_s));
          }
          motion.keyframes.push_back(keyframe);
        }
        return motion;
      }
      case 2: {
        check_keys(
            map,
            {"type", "centre", "radius_m", "period_s", "phase_deg", "plane", "tilt_deg", "rpy_deg"},
            "an orbit trajectory");
        OrbitTrajectory motion;
        motion.centre = vector<3>(required(map, "centre", "an orbit trajectory"), "centre");
        motion.radius_m = number(map, "radius_m", motion.radius_m, 0, kFar);
        motion.period_s = positive(map, "period_s", motion.period_s, kFar);
        motion.phase_deg = number(map, "phase_deg", motion.phase_deg, -kFar, kFar);
        motion.plane =
            static_cast<OrbitTrajectory::Plane>(choice(map, "plane", {"frontal", "horizontal"}, 0));
        motion.tilt_deg = number(map, "tilt_deg", motion.tilt_deg, -90, 90);
        motion.rpy_deg = vector<3>(map, "rpy_deg", motion.rpy_deg);
        return motion;
      }
      case 3: {
        check_keys(
            map, {"type", "from", "to", "speed_mps", "yaw_swing_deg", "swing_period_s", "rpy_deg"},
            "a walk trajectory");
        WalkTrajectory motion;
        motion.from = vector<3>(required(map, "from", "a walk trajectory"), "from");
        motion.to = vector<3>(required(map, "to", "a walk trajectory"), "to");
        motion.speed_mps = positive(map, "speed_mps", motion.speed_mps, kFar);
        motion.yaw_swing_deg = number(map, "yaw_swing_deg", motion.yaw_swing_deg, -180, 180);
        motion.swing_period_s = number(map, "swing_period_s", motion.swing_period_s, 0, kFar);
        motion.rpy_deg = vector<3>(map, "rpy_deg", motion.rpy_deg);
        return motion;
      }
      default: {
        check_keys(map, {"type", "position", "axis", "rate_deg_s", "rpy_deg"}, "a spin trajectory");
        SpinTrajectory motion;
        motion.position = vector<3>(required(map, "position", "a spin trajectory"), "position");
        motion.axis = vector<3>(map, "axis", motion.axis);
        if (!(motion.axis.norm() > 1e-9)) fail(map["axis"], "'axis' must not be zero");
        motion.rate_deg_s = number(map, "rate_deg_s", motion.rate_deg_s, -kFar, kFar);
        motion.rpy_deg = vector<3>(map, "rpy_deg", motion.rpy_deg);
        return motion;
      }
    }
  }

  Distractors read_distractors(const YAML::Node& map) const {
    check_keys(map, {"blobs", "hot_points", "lamp", "occluders"}, "'distractors'");
    Distractors distractors;
    if (YAML::Node blobs = map["blobs"]) {
      if (!blobs.IsSequence()) fail(blobs, "'blobs' must be a list");
      for (const YAML::Node& node : blobs) {
        check_keys(node, {"shape", "position_px", "size_px", "angle_deg", "brightness_dn"},
                   "a blob");
        Blob blob;
        blob.shape = static_cast<Blob::Shape>(choice(node, "shape", {"ellipse", "rectangle"}, 0));
        blob.centre_px = vector<2>(required(node, "position_px", "a blob"), "position_px");
        blob.size_px = vector<2>(node, "size_px", blob.size_px);
        if (!(blob.size_px.minCoeff() > 0)) fail(node["size_px"], "'size_px' must be positive");
        blob.angle_deg = number(node, "angle_deg", blob.angle_deg, -360, 360);
        blob.brightness_dn = number(node, "brightness_dn", blob.brightness_dn, 0, 1000);
        distractors.blobs.push_back(blob);
      }
    }
    if (YAML::Node points = map["hot_points"]) {
      check_keys(points, {"count", "brightness_dn", "fixed"}, "'hot_points'");
      HotPoints& hot = distractors.hot_points;
      hot.count = static_cast<int>(integer(points, "count", 0, 0, 100000));
      hot.brightness_dn = number(points, "brightness_dn", hot.brightness_dn, 0, 1000);
      hot.fixed = boolean(points, "fixed", hot.fixed);
    }
    if (YAML::Node node = map["lamp"]) {
      check_keys(node, {"position_px", "radius_px", "brightness_dn", "glow_px"}, "'lamp'");
      Lamp lamp;
      lamp.centre_px = vector<2>(required(node, "position_px", "'lamp'"), "position_px");
      lamp.radius_px = positive(node, "radius_px", lamp.radius_px, 10000);
      lamp.brightness_dn = number(node, "brightness_dn", lamp.brightness_dn, 0, 1000);
      lamp.glow_px = number(node, "glow_px", lamp.glow_px, 0, 10000);
      distractors.lamp = lamp;
    }
    if (YAML::Node occluders = map["occluders"]) {
      if (!occluders.IsSequence()) fail(occluders, "'occluders' must be a list");
      for (const YAML::Node& node : occluders) {
        check_keys(node, {"position_px", "size_px", "level_dn"}, "an occluder");
        Occluder occluder;
        occluder.corner_px = vector<2>(required(node, "position_px", "an occluder"), "position_px");
        occluder.size_px = vector<2>(required(node, "size_px", "an occluder"), "size_px");
        if (!(occluder.size_px.minCoeff() > 0)) fail(node["size_px"], "'size_px' must be positive");
        occluder.level_dn = number(node, "level_dn", occluder.level_dn, -1, 255);
        distractors.occluders.push_back(occluder);
      }
    }
    return distractors;
  }

  const constellations::ConstellationDatabase& database_;
};

}  // namespace

std::optional<std::string> RenderOptions::problem() const {
  if (!(marker_diameter_m > 0)) {
    return fmt::format("marker_diameter_m: {} is not above 0", marker_diameter_m);
  }
  if (!(exposure >= 0)) return fmt::format("exposure: {} is below 0", exposure);
  if (!(noise_sigma_dn >= 0)) return fmt::format("noise_sigma_dn: {} is below 0", noise_sigma_dn);
  if (!(blur_sigma_px >= 0)) return fmt::format("blur_sigma_px: {} is below 0", blur_sigma_px);
  if (!(motion_blur_s >= 0)) return fmt::format("motion_blur_s: {} is below 0", motion_blur_s);
  if (motion_blur_steps < 0) {
    return fmt::format("motion_blur_steps: {} is below 0", motion_blur_steps);
  }
  if (supersampling < 1) return fmt::format("supersampling: {} is below 1", supersampling);
  return std::nullopt;
}

Scene parse_scene(const std::string& text, const std::string& source,
                  const constellations::ConstellationDatabase& database) {
  YAML::Node root = YamlReader<SceneError>(source).parse(text);
  if (!root || root.IsNull()) throw SceneError(source + ": the scene is empty");
  return SceneReader(source, database).read(root);
}

Scene load_scene(const std::string& path, const constellations::ConstellationDatabase& database) {
  std::ifstream file(path);
  if (!file) {
    throw SceneError(fmt::format("{}: cannot read the scene: {}", path, std::strerror(errno)));
  }
  std::stringstream text;
  text << file.rdbuf();
  return parse_scene(text.str(), path, database);
}

double ObjectOcclusion::fraction_at(double time_s) const {
  if (!(period_s > 0) || max_fraction <= fraction) return fraction;
  return fraction + (max_fraction - fraction) * 0.5 * (1 - std::cos(2 * M_PI * time_s / period_s));
}

}  // namespace mocap::synthetic
