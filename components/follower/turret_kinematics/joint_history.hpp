// The turret's joint angles over the last moments, so that an object seen in an image is
// placed with the angles the turret had when the image was taken, not the ones it has when the
// pose arrives (tens of milliseconds later, while the turret turns).
#pragma once

#include <cstdint>
#include <deque>
#include <optional>

#include "follower/turret_kinematics/turret_model.hpp"

namespace mocap::turret {

class JointHistory {
 public:
  // Keeps the readings of the last `span_ns` (1 s by default).
  explicit JointHistory(int64_t span_ns = 1'000'000'000) : span_ns_(span_ns) {}

  // A reading taken at `stamp_ns`; older than the newest one: ignored.
  void add(int64_t stamp_ns, const JointAngles& angles);

  // The angles at `stamp_ns`: linear between the readings around it; the oldest or newest
  // kept reading outside them; nothing before the first reading.
  std::optional<JointAngles> at(int64_t stamp_ns) const;

  std::optional<JointAngles> latest() const;

 private:
  struct Reading {
    int64_t stamp_ns;
    JointAngles angles;
  };
  int64_t span_ns_;
  std::deque<Reading> readings_;
};

}  // namespace mocap::turret
