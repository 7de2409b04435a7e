#include <mocap/calibration/board_recording.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace mocap::calibration {
namespace {

int64_t to_ns(double seconds) { return static_cast<int64_t>(std::llround(seconds * 1e9)); }

// A blink still collecting samples.
struct OpenBlink {
  Blink blink;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  Eigen::Vector2d mean() const { return sum / blink.samples; }
};

// Within one cycle, blinks start 1, 2 or 3 periods apart (LEDs between them unseen); anything
// else crosses the pause or is not the board at all. Returns the periods, 0 for "anything else".
int periods_between(int64_t from_ns, int64_t to_ns, const ShotOptions& options) {
  const double interval_s = static_cast<double>(to_ns - from_ns) * 1e-9;
  const double periods = std::round(interval_s / options.period_s);
  if (periods < 1 || periods > 3) return 0;
  if (std::abs(interval_s - periods * options.period_s) > options.tolerance_s) return 0;
  return static_cast<int>(periods);
}

void validate(const ShotOptions& options) {
  if (!(options.period_s > 0) || !std::isfinite(options.period_s)) {
    throw std::invalid_argument("period_s must be positive");
  }
  if (!(options.tolerance_s > 0) || !(options.tolerance_s < options.period_s / 4)) {
    throw std::invalid_argument("tolerance_s must be above 0 and below period_s / 4");
  }
  // A pause of whole periods would look like missing LEDs, and the cycle start would be lost.
  const double periods = options.pause_s / options.period_s;
  const double off_whole = std::abs(periods - std::round(periods)) * options.period_s;
  if (!std::isfinite(options.pause_s) || !(off_whole > 2 * options.tolerance_s)) {
    throw std::invalid_argument(
        "pause_s must lie more than two tolerances from every whole number of periods "
        "(e.g. 1.5 periods)");
  }
}

}  // namespace

std::vector<Blink> average_blinks(std::span<const RawPoint> points, const BlinkOptions& options,
                                  BlinkStats* stats) {
  if (!(options.pixel_tolerance > 0) || !(options.max_gap_s > 0) || options.min_samples < 1) {
    throw std::invalid_argument(
        "blink options: pixel_tolerance and max_gap_s must be positive, min_samples at least 1");
  }
  const int64_t max_gap_ns = to_ns(options.max_gap_s);
  BlinkStats counts;
  counts.points = points.size();
  std::vector<Blink> blinks;
  auto close = [&](const OpenBlink& open) {
    if (open.blink.samples < options.min_samples) {
      ++counts.glitches;
      return;
    }
    Blink blink = open.blink;
    blink.pixel = open.mean();
    blinks.push_back(blink);
  };
  std::map<int, std::vector<OpenBlink>> open_by_camera;
  for (const RawPoint& point : points) {
    std::vector<OpenBlink>& open = open_by_camera[point.camera_id];
    auto stale = std::stable_partition(open.begin(), open.end(), [&](const OpenBlink& b) {
      return point.stamp_ns - b.blink.end_ns <= max_gap_ns;
    });
    std::for_each(stale, open.end(), close);
    open.erase(stale, open.end());
    OpenBlink* best = nullptr;
    double best_distance = options.pixel_tolerance;
    for (OpenBlink& candidate : open) {
      // Two points of one sample are two LEDs, however close.
      if (candidate.blink.end_ns == point.stamp_ns) continue;
      const double distance = (candidate.mean() - point.pixel).norm();
      if (distance <= best_distance) {
        best = &candidate;
        best_distance = distance;
      }
    }
    if (best == nullptr) {
      OpenBlink fresh;
      fresh.blink.camera_id = point.camera_id;
      fresh.blink.start_ns = point.stamp_ns;
      open.push_back(fresh);
      best = &open.back();
    }
    best->sum += point.pixel;
    best->blink.end_ns = point.stamp_ns;
    ++best->blink.samples;
  }
  for (const auto& [camera, open] : open_by_camera) std::for_each(open.begin(), open.end(), close);
  std::stable_sort(blinks.begin(), blinks.end(), [](const Blink& a, const Blink& b) {
    return a.start_ns != b.start_ns ? a.start_ns < b.start_ns : a.camera_id < b.camera_id;
  });
  counts.blinks = blinks.size();
  if (stats != nullptr) *stats = counts;
  return blinks;
}

std::vector<BoardShot> group_shots(std::span<const Blink> blinks, const ShotOptions& options,
                                   ShotStats* stats) {
  validate(options);
  std::map<int, std::vector<const Blink*>> by_camera;
  for (const Blink& blink : blinks) by_camera[blink.camera_id].push_back(&blink);
  ShotStats counts;
  std::vector<BoardShot> shots;
  for (auto& entry : by_camera) {
    // Named, not a structured binding: clang 14 cannot capture those in the lambda below.
    const int camera = entry.first;
    std::vector<const Blink*>& list = entry.second;
    std::stable_sort(list.begin(), list.end(),
                     [](const Blink* a, const Blink* b) { return a->start_ns < b->start_ns; });
    // A run: blinks 1 to 3 periods apart, at most one cycle's worth (3 periods) in all.
    std::vector<const Blink*> run;
    int span = 0;
    auto finish = [&]() {
      if (run.empty()) return;
      if (span > 3) {
        ++counts.overlong_runs;
      } else if (run.size() == 4) {
        BoardShot shot;
        shot.camera_id = camera;
        shot.stamp_ns = run.front()->start_ns;
        for (size_t i = 0; i < 4; ++i) shot.points[i] = run[i]->pixel;
        shots.push_back(shot);
        ++counts.shots;
        ++counts.shots_per_camera[camera];
      } else {
        ++counts.dropped_cycles;
      }
      run.clear();
      span = 0;
    };
    for (const Blink* blink : list) {
      const int periods =
          run.empty() ? 0 : periods_between(run.back()->start_ns, blink->start_ns, options);
      if (periods == 0) finish();
      run.push_back(blink);
      span += periods;
    }
    finish();
  }
  std::stable_sort(shots.begin(), shots.end(), [](const BoardShot& a, const BoardShot& b) {
    return a.stamp_ns != b.stamp_ns ? a.stamp_ns < b.stamp_ns : a.camera_id < b.camera_id;
  });
  if (stats != nullptr) *stats = counts;
  return shots;
}

std::vector<std::vector<BoardShot>> group_frames(std::span<const BoardShot> shots,
                                                 const ShotOptions& options) {
  std::vector<BoardShot> sorted(shots.begin(), shots.end());
  std::stable_sort(sorted.begin(), sorted.end(), [](const BoardShot& a, const BoardShot& b) {
    return a.stamp_ns != b.stamp_ns ? a.stamp_ns < b.stamp_ns : a.camera_id < b.camera_id;
  });
  const int64_t window_ns = to_ns(options.period_s / 2);
  std::vector<std::vector<BoardShot>> frames;
  for (const BoardShot& shot : sorted) {
    const bool joins =
        !frames.empty() && shot.stamp_ns - frames.back().front().stamp_ns <= window_ns &&
        std::none_of(frames.back().begin(), frames.back().end(),
                     [&](const BoardShot& other) { return other.camera_id == shot.camera_id; });
    if (!joins) frames.emplace_back();
    frames.back().push_back(shot);
  }
  for (auto& frame : frames) {
    std::stable_sort(frame.begin(), frame.end(), [](const BoardShot& a, const BoardShot& b) {
      return a.camera_id < b.camera_id;
    });
  }
  return frames;
}

void write_data_file(const std::string& path, std::span<const BoardShot> shots,
                     const std::map<int, std::string>& camera_names, const ShotOptions& options) {
  auto name_of = [&](int camera_id) {
    auto found = camera_names.find(camera_id);
    return found != camera_names.end() ? found->second : "camera" + std::to_string(camera_id);
  };
  auto rounded = [](double pixel) { return std::round(pixel * 1000) / 1000; };
  std::string text = "[";
  const auto frames = group_frames(shots, options);
  for (size_t f = 0; f < frames.size(); ++f) {
    text += f == 0 ? "\n  [" : ",\n  [";
    for (size_t s = 0; s < frames[f].size(); ++s) {
      const BoardShot& shot = frames[f][s];
      nlohmann::ordered_json entry;
      entry["camera"] = name_of(shot.camera_id);
      entry["stamp_ns"] = shot.stamp_ns;
      entry["points"] = nlohmann::ordered_json::array();
      for (const Eigen::Vector2d& point : shot.points) {
        entry["points"].push_back({rounded(point.x()), rounded(point.y())});
      }
      text += (s == 0 ? "\n    " : ",\n    ") + entry.dump();
    }
    text += "\n  ]";
  }
  text += frames.empty() ? "]\n" : "\n]\n";
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (out) out.write(text.data(), static_cast<std::streamsize>(text.size()));
  if (out) out.close();
  if (!out) {
    throw std::runtime_error(path + ": cannot write the data file: " + std::strerror(errno));
  }
}

}  // namespace mocap::calibration
