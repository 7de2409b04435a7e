// From the PixArt cameras' raw points to the calibration's data file (seed 002 §7.2–7.3).
//
// The calibration board has four LEDs that light one at a time, LED 0, 1, 2, 3, each for
// `on_s` then dark for `off_s` (one period, 0.2 s), and then all stay dark for a further
// pause (0.3 s) before LED 0 lights again. A camera sees a continuing stream of samples of
// each lit LED; average_blinks turns each stream into one blink (its mean pixel), and
// group_shots turns each camera's four blinks of one cycle into a shot, the board's four
// points in LED order.
//
// Which blink is LED 0: with one LED at a time, a square board looks the same from whichever
// LED the cycle starts, so only time can tell. The pause marks it: within a cycle, blinks start
// a whole number of periods apart; across the pause the interval is a whole number of periods
// plus the pause. The pause is not itself a whole number of periods (1.5 by default), so a
// missing LED cannot be mistaken for it, and each cycle is exactly the blinks between two
// intervals that are not a whole number of periods. Four blinks one period apart there are
// LEDs 0 to 3; a cycle with fewer is dropped (a blink missing) and counted. A board without
// the pause gives runs longer than a cycle, dropped too (ShotStats::overlong_runs). The
// simulated box's calibration boards (config/pixart/README.md, `pause_s`) and a real board's
// firmware must keep this pattern.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace mocap::calibration {

// One point one camera reported.
struct RawPoint {
  int64_t stamp_ns = 0;
  int camera_id = 0;
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
};

// One LED's lit spell as one camera saw it.
struct Blink {
  int camera_id = 0;
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // the mean of its samples
  int64_t start_ns = 0, end_ns = 0;                 // its first and last sample
  int samples = 0;
};

struct BlinkOptions {
  // A sample joins a blink of its camera when it lies within this distance of the blink's
  // mean so far (not of its last sample: a board moved during a blink then splits it, and the
  // pieces' timing spoils their cycle, rather than a smeared point entering the data).
  double pixel_tolerance = 3;
  // Longer without a sample ends the blink (the board's dark time is longer).
  double max_gap_s = 0.03;
  // Blinks of fewer samples are glitches (a reflection, a flicker) and are dropped.
  int min_samples = 5;
};

struct BlinkStats {
  size_t points = 0;    // raw points read
  size_t blinks = 0;    // blinks kept
  size_t glitches = 0;  // blinks dropped for too few samples
};

// The blinks of `points`, which are in the order they were received (time order per camera;
// the cameras may interleave). Output is ordered by start time (ties: by camera). Throws
// std::invalid_argument for options that are not positive.
std::vector<Blink> average_blinks(std::span<const RawPoint> points,
                                  const BlinkOptions& options = {}, BlinkStats* stats = nullptr);

// The board in one cycle as one camera saw it.
struct BoardShot {
  int camera_id = 0;
  int64_t stamp_ns = 0;                     // when LED 0 lit
  std::array<Eigen::Vector2d, 4> points{};  // LED 0, 1, 2, 3
};

struct ShotOptions {
  double period_s = 0.2;      // from one LED lighting to the next: on_s + off_s
  double pause_s = 0.3;       // the further dark time after LED 3
  double tolerance_s = 0.03;  // on the interval between blink starts
};

struct ShotStats {
  size_t shots = 0;
  // Cycles a camera saw part of: at least one blink, not all four.
  size_t dropped_cycles = 0;
  // Runs of blinks one period apart that go on for longer than a cycle: the board does not
  // pause after LED 3, or the options do not match it.
  size_t overlong_runs = 0;
  std::map<int, size_t> shots_per_camera;
};

// The shots in `blinks` (any order), ordered by stamp, then camera. Throws
// std::invalid_argument unless 0 < tolerance_s < period_s / 4 and the pause lies more than two
// tolerances from every whole number of periods.
std::vector<BoardShot> group_shots(std::span<const Blink> blinks, const ShotOptions& options = {},
                                   ShotStats* stats = nullptr);

// The shots grouped into frames by time: shots of different cameras whose stamps lie within
// half a period of a frame's first shot are that frame's (the board stood in one place for all
// of them, which ties the cameras together in a stereo calibration). Frames in time order,
// cameras in each by id.
std::vector<std::vector<BoardShot>> group_frames(std::span<const BoardShot> shots,
                                                 const ShotOptions& options = {});

// Writes the frames of `shots` (group_frames) as a data file (calibration_config.hpp), the
// cameras named by `camera_names` (camera_id -> name; a camera missing there is
// "camera<id>"), pixels to 1/1000. Throws std::runtime_error "PATH: cannot write ...".
void write_data_file(const std::string& path, std::span<const BoardShot> shots,
                     const std::map<int, std::string>& camera_names,
                     const ShotOptions& options = {});

}  // namespace mocap::calibration
