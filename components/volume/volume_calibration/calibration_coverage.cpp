#include "volume/volume_calibration/calibration_coverage.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace mocap::volume {
namespace {

constexpr int kMaxCameras = 64;  // whole_at_'s bits
// How long a capture time is kept waiting for other cameras' sightings of it.
constexpr int64_t kKeepNs = 2'000'000'000;

}  // namespace

std::optional<std::string> CoverageOptions::problem() const {
  if (views_per_region < 1)
    return fmt::format("views_per_region: {} (1 or more)", views_per_region);
  if (shared_shots < 0) return fmt::format("shared_shots: {} (0 or more)", shared_shots);
  if (!(same_capture_s >= 0)) return fmt::format("same_capture_s: {} (0 or more)", same_capture_s);
  return std::nullopt;
}

const char* region_name(int region) {
  static const char* const kNames[kCoverageRegions] = {
      "upper left corner", "top edge",          "upper right corner", "left edge",         "centre",
      "right edge",        "lower left corner", "bottom edge",        "lower right corner"};
  return region >= 0 && region < kCoverageRegions ? kNames[region] : "?";
}

CalibrationCoverage::CalibrationCoverage(const std::vector<CoverageCamera>& cameras,
                                         const CoverageOptions& options)
    : options_(options) {
  if (auto problem = options.problem()) throw std::invalid_argument(*problem);
  if (cameras.size() > kMaxCameras) {
    throw std::invalid_argument(fmt::format("{} cameras: at most {}", cameras.size(), kMaxCameras));
  }
  for (const CoverageCamera& camera : cameras) {
    if (camera.image_size.x() <= 0 || camera.image_size.y() <= 0) {
      throw std::invalid_argument(fmt::format("camera {}: an image of {}x{} pixels", camera.name,
                                              camera.image_size.x(), camera.image_size.y()));
    }
    CameraCoverage coverage;
    coverage.name = camera.name;
    coverage.image_size = camera.image_size;
    update_progress(coverage);
    cameras_.push_back(std::move(coverage));
  }
}

void CalibrationCoverage::add(const BoardSighting& sighting) {
  if (sighting.camera >= cameras_.size()) return;
  latest_stamp_ns_ = std::max(latest_stamp_ns_, sighting.stamp_ns);
  CameraCoverage& camera = cameras_[sighting.camera];
  std::array<bool, kCoverageRegions> touched{};
  bool whole = !sighting.pixels.empty();
  for (const auto& pixel : sighting.pixels) {
    if (!pixel) {
      whole = false;
      continue;
    }
    const double column = 3 * pixel->x() / camera.image_size.x();
    const double row = 3 * pixel->y() / camera.image_size.y();
    if (!(column >= 0 && column < 3 && row >= 0 && row < 3)) continue;  // off the image
    touched[static_cast<size_t>(3 * static_cast<int>(row) + static_cast<int>(column))] = true;
  }
  for (int r = 0; r < kCoverageRegions; ++r) {
    if (touched[static_cast<size_t>(r)]) ++camera.views[static_cast<size_t>(r)];
  }
  if (whole) {
    // The capture time it belongs to: one within same_capture_s, else its own.
    const auto tolerance = static_cast<int64_t>(std::llround(options_.same_capture_s * 1e9));
    auto at = whole_at_.lower_bound(sighting.stamp_ns - tolerance);
    if (at == whole_at_.end() || at->first > sighting.stamp_ns + tolerance) {
      at = whole_at_.emplace(sighting.stamp_ns, 0).first;
    }
    const uint64_t bit = uint64_t{1} << sighting.camera;
    if ((at->second & bit) == 0) {
      // The second camera at a capture time makes it a shared shot for both; each later one
      // for itself.
      if (std::popcount(at->second) == 1) {
        CameraCoverage& first = cameras_[static_cast<size_t>(std::countr_zero(at->second))];
        ++first.shared_shots;
        update_progress(first);
      }
      if (at->second != 0) ++camera.shared_shots;
      at->second |= bit;
    }
    // Capture times long past: no camera's sighting of them is still on its way.
    whole_at_.erase(whole_at_.begin(), whole_at_.lower_bound(sighting.stamp_ns - kKeepNs));
  }
  update_progress(camera);
}

void CalibrationCoverage::update_progress(CameraCoverage& camera) const {
  const auto needed = static_cast<uint32_t>(options_.views_per_region);
  const auto shared = static_cast<uint32_t>(options_.shared_shots);
  uint32_t have = std::min(camera.shared_shots, shared);
  camera.missing.clear();
  for (int r = 0; r < kCoverageRegions; ++r) {
    const uint32_t views = camera.views[static_cast<size_t>(r)];
    have += std::min(views, needed);
    if (views < needed) camera.missing.push_back(region_name(r));
  }
  if (camera.shared_shots < shared) camera.missing.push_back("shots with another camera");
  camera.progress = static_cast<double>(have) / (kCoverageRegions * needed + shared);
}

double least_progress(const std::vector<CameraCoverage>& cameras) {
  double least = cameras.empty() ? 0 : 1;
  for (const CameraCoverage& camera : cameras) least = std::min(least, camera.progress);
  return least;
}

std::string coverage_line(const CameraCoverage& camera) {
  return fmt::format("{} {}{}{}", camera.name, progress_bar(camera.progress),
                     camera.missing.empty() ? "" : ": missing ", fmt::join(camera.missing, ", "));
}

std::string progress_bar(double fraction, int width) {
  fraction = std::clamp(fraction, 0.0, 1.0);
  const int filled = static_cast<int>(std::floor(fraction * width));
  return fmt::format("[{}{}] {:3d} %", std::string(static_cast<size_t>(filled), '='),
                     std::string(static_cast<size_t>(width - filled), ' '),
                     static_cast<int>(std::floor(fraction * 100)));
}

}  // namespace mocap::volume
