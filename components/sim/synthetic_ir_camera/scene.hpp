// What the synthetic IR camera sees: constellations moving along trajectories, how the sensor
// renders them, and the bright or dark things that are not markers. Read from a scene YAML
// file; config/scenes/README.md documents every key.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "sim/synthetic_ir_camera/trajectory.hpp"
#include "tracking/constellation_database/constellation_database.hpp"

namespace mocap::synthetic {

// Hides the part of an object's image on one side: a hand or a pole in front of the board.
// The covered region is a fraction of the bounding box of the object's markers in the image,
// measured from `side`, and moves with the object. With a period, the fraction swings from
// `fraction` to `max_fraction` and back (a hand passing over the board), starting at
// `fraction` at time 0.
struct ObjectOcclusion {
  enum class Side { Left, Right, Top, Bottom };
  double fraction = 0;  // 0..1
  Side side = Side::Left;
  double max_fraction = 0;  // 0..1; below `fraction`: no swing
  double period_s = 0;      // 0 = no swing

  // The fraction hidden at scene time `time_s`.
  double fraction_at(double time_s) const;
};

struct SceneObject {
  std::string constellation;  // name in the database
  // Marker centres in the constellation frame (metres), copied from the database.
  std::vector<Eigen::Vector3d> markers;
  Trajectory trajectory = StaticTrajectory{};
  std::optional<ObjectOcclusion> occlusion;
};

// How the sensor turns light into digital numbers (DN, 0..255).
struct RenderOptions {
  double marker_diameter_m = 0.015;  // flat retro-reflective discs in the board's plane
  // Peak brightness of a fully covered pixel above the background, as a fraction of 255: at
  // 1.0 the centre of a marker saturates.
  double exposure = 1.0;
  double background_dn = 8;    // dark level of the sensor
  double noise_sigma_dn = 2;   // Gaussian read noise, whole image
  double blur_sigma_px = 0.6;  // optics and pixel cross-talk (Gaussian); 0 = none
  double motion_blur_s = 0;    // exposure time; 0 = instantaneous
  int motion_blur_steps = 0;   // sub-poses over the exposure; 0 = enough for 0.25 px steps
  int supersampling = 4;       // rays per pixel side on a marker's edge (4 = 16 rays)

  // Why these options cannot be used, naming the field ("supersampling: 0 is below 1");
  // nullopt when they can. IrRenderer's constructor throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

// A bright shape that is not a marker: a reflection, a screen, a strip light.
struct Blob {
  enum class Shape { Ellipse, Rectangle };
  Shape shape = Shape::Ellipse;
  Eigen::Vector2d centre_px{0, 0};
  Eigen::Vector2d size_px{40, 8};  // full length along `angle_deg`, full width across it
  double angle_deg = 0;            // of the length axis, from image +x towards +y
  double brightness_dn = 230;      // above the background
};

// Isolated single bright pixels (hot pixels, glints).
struct HotPoints {
  int count = 0;
  double brightness_dn = 255;  // above the background
  // true: the same pixels in every frame (drawn once from the scene's seed); false: new
  // pixels every frame.
  bool fixed = false;
};

// A large bright disc with a glow around it: a lamp, the sun through a window.
struct Lamp {
  Eigen::Vector2d centre_px{0, 0};
  double radius_px = 30;
  double brightness_dn = 255;  // above the background
  // The glow falls off as a Gaussian of this sigma beyond the disc's edge; 0 = no glow.
  double glow_px = 20;
};

// An opaque rectangle in front of everything (image space): what lies behind it is not seen.
struct Occluder {
  Eigen::Vector2d corner_px{0, 0};  // top-left
  Eigen::Vector2d size_px{100, 100};
  double level_dn = -1;  // its own brightness; negative = the background level
};

struct Distractors {
  std::vector<Blob> blobs;
  HotPoints hot_points;
  std::optional<Lamp> lamp;
  std::vector<Occluder> occluders;
};

struct Scene {
  std::string source;  // the file it came from
  std::vector<SceneObject> objects;
  RenderOptions render;
  Distractors distractors;
  uint64_t seed = 1;  // every random draw (noise, hot points) follows from it
};

// Why a scene cannot be used: one line, "FILE:LINE: what is wrong".
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Reads a scene file; constellation names are looked up in `database`. Throws SceneError for
// a missing or unreadable file, bad YAML, unknown keys, wrong types, values out of range and
// unknown constellations.
Scene load_scene(const std::string& path, const constellations::ConstellationDatabase& database);
// The same for text in memory; `source` names it in errors.
Scene parse_scene(const std::string& text, const std::string& source,
                  const constellations::ConstellationDatabase& database);

}  // namespace mocap::synthetic
