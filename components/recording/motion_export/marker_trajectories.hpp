// Each marker's positions over a recording, gathered from marker clouds in the order they come:
// a labeled marker by its body and its index in that body, an unlabeled one by its track. What
// the export formats write beside the bodies (point_table.hpp). Middleware-free.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace mocap::motion_export {

// Orders labeled markers by body and index, then unlabeled ones by track.
struct MarkerKey {
  std::string body;     // empty: unlabeled
  uint32_t number = 0;  // labeled: its index in the body's markers; unlabeled: its track's id

  bool labeled() const { return !body.empty(); }
  // "<body>_<index + 1>" as the NatNet server names a body's markers, or "unlabeled_<track>".
  std::string name() const;
  // "marker 2 of drone" or "unlabeled, track 1234".
  std::string description() const;
  bool operator<(const MarkerKey& other) const;
};

struct MarkerSample {
  int64_t stamp_ns = 0;                                // capture time
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // world frame, metres
  uint32_t cameras = 0;                                // bit c: the volume's camera c saw it
};

class MarkerTrajectories {
 public:
  void add(const MarkerKey& key, const MarkerSample& sample) { markers_[key].push_back(sample); }
  const std::map<MarkerKey, std::vector<MarkerSample>>& markers() const { return markers_; }

 private:
  std::map<MarkerKey, std::vector<MarkerSample>> markers_;
};

}  // namespace mocap::motion_export
