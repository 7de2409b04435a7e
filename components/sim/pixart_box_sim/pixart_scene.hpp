// What the simulated PixArt box sees: the rig's robots moving along floor trajectories, and
// the seed's 4-LED calibration boards. Read from a scene YAML file (config/pixart/scenes/);
// config/pixart/README.md documents every key.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "pixart/pixart_rig/pixart_rig.hpp"
#include "sim/pixart_box_sim/floor_trajectory.hpp"

namespace mocap::pixart {

// Something carrying LEDs on the floor: a robot of the rig or a calibration board.
struct SceneObject {
  enum class Kind { Robot, CalibrationBoard };
  std::string name;  // unique in the scene; a robot's is its name in the rig
  Kind kind = Kind::Robot;
  // In the object's frame (x forward, y left, metres), with their blink timing; the order is
  // the order the sensor reports them in when it sees more than it can report.
  std::vector<Led> leds;
  FloorTrajectory trajectory = StaticFloorTrajectory{};
  double height_m = 0.45;  // of the LEDs above the floor
};

struct PixartScene {
  std::string source;                // the file it came from
  std::vector<SceneObject> objects;  // robots in file order, then boards in file order
};

// Why a scene file cannot be used: "FILE:LINE: what".
class PixartSceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The seed's calibration board (seed 002 §7.3): four LEDs at the corners of a square of side
// `size_m`, centred on the board's origin, lit one at a time: LED i is on for `on_s` starting
// at i·(on_s + off_s) of each cycle of 4·(on_s + off_s) + pause_s, so that a camera sees
// exactly one LED (or none) at any time and the calibration knows which corner it is. LED 0 is
// at (−s/2, −s/2), then counter-clockwise: (s/2, −s/2), (s/2, s/2), (−s/2, s/2). The pause
// after LED 3 tells the recording which LED starts the cycle (board_recording.hpp, 0.3 s there);
// 0 is the seed's board, whose cycle has no mark.
std::vector<Led> calibration_board_leds(double size_m, double on_s = 0.1, double off_s = 0.1,
                                        double pause_s = 0);

// Reads a scene; robots are looked up in `rig` by name (their LED layouts) and carry their
// LEDs at rig.led_plane_height_m. Throws PixartSceneError "FILE:LINE: what" for unknown or
// repeated keys, wrong types, values out of range, robots the rig lacks or that appear twice.
PixartScene load_pixart_scene(const std::string& path, const Rig& rig);
PixartScene parse_pixart_scene(const std::string& text, const std::string& source, const Rig& rig);

}  // namespace mocap::pixart
