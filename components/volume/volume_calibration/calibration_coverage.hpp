// How far a waved calibration session has come, camera by camera, before the solve: the board
// seen in every part of each camera's image (a camera's pose is fitted from where its pixels
// fall; a session that only ever showed the board in the middle of an image leaves the edges to
// chance), and seen whole at the same time by another camera (what ties the cameras together in
// the solve, volume_calibration.hpp). What a person waving the board watches: each camera's
// regions filling in, a progress figure, and what is still missing ("lower left corner").
//
//   CalibrationCoverage coverage({{"cam_0", {1280, 720}}, ...});
//   for each sighting: coverage.add(sighting);
//   coverage.camera(c).progress, coverage.camera(c).missing
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "volume/volume_calibration/volume_calibration.hpp"

namespace mocap::volume {

struct CoverageOptions {
  // Sightings each of the nine regions of an image needs.
  int views_per_region = 10;
  // Capture times a camera needs with the board whole in it and in another camera.
  int shared_shots = 30;
  // Sightings whose stamps differ by no more than this are one capture time (as the solve's
  // VolumeCalibrationOptions::same_capture_s).
  double same_capture_s = 0.002;

  // Why these options cannot be used, naming the field; nullopt when they can.
  std::optional<std::string> problem() const;
};

// An image in a 3 x 3 grid, row by row from the top left: what a region is called.
inline constexpr int kCoverageRegions = 9;
const char* region_name(int region);  // "upper left corner", "top edge", ..., "centre", ...

struct CameraCoverage {
  std::string name;
  Eigen::Vector2i image_size = Eigen::Vector2i::Zero();
  // Sightings with a board marker in each region (a sighting counts once in each region it
  // touches), row by row from the top left.
  std::array<uint32_t, kCoverageRegions> views{};
  uint32_t shared_shots = 0;  // capture times with the board whole here and in another camera
  // 0 to 1: each region's views up to views_per_region and the shared shots up to shared_shots,
  // all counted alike. 1: complete.
  double progress = 0;
  // What keeps it from 1: "lower left corner" for each region short of views, "shots with
  // another camera" when those are short; empty when complete.
  std::vector<std::string> missing;
};

struct CoverageCamera {
  std::string name;
  Eigen::Vector2i image_size = Eigen::Vector2i::Zero();
};

// The least complete camera's progress: a session is as far as its worst camera (0 for none).
double least_progress(const std::vector<CameraCoverage>& cameras);

// "cam_0 [=====               ]  25 %: missing lower left corner, bottom edge": a camera's bar
// and what it still needs, as the command line and the log show it.
std::string coverage_line(const CameraCoverage& camera);

class CalibrationCoverage {
 public:
  // Throws std::invalid_argument for options that cannot be used or an image of no size.
  explicit CalibrationCoverage(const std::vector<CoverageCamera>& cameras,
                               const CoverageOptions& options = {});

  // A camera's view of the board (its index into the cameras). Sightings may come in any order
  // across cameras, each camera's in the order of its stamps.
  void add(const BoardSighting& sighting);

  // In the order of the cameras given.
  const std::vector<CameraCoverage>& cameras() const { return cameras_; }
  double progress() const { return least_progress(cameras_); }
  // The capture time of the latest sighting added (0 before any): what the coverage is as of.
  int64_t latest_stamp_ns() const { return latest_stamp_ns_; }

 private:
  void update_progress(CameraCoverage& camera) const;

  CoverageOptions options_;
  std::vector<CameraCoverage> cameras_;
  // Recent capture times: the cameras that saw the board whole at each (a bit per camera).
  std::map<int64_t, uint64_t> whole_at_;
  int64_t latest_stamp_ns_ = 0;
};

// "[=========           ] 45 %": `fraction` (0 to 1) as a bar of `width` characters.
std::string progress_bar(double fraction, int width = 20);

}  // namespace mocap::volume
