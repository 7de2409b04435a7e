// Groups a camera's decoded points into samples: the sensor's four slots at one instant,
// which arrive as two frames (slots 0–1, then 2–3).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include "pixart/pixart_bridge/pixart_bridge.hpp"

namespace mocap::pixart {

struct CameraSample {
  uint16_t camera_id = 0;
  int64_t stamp_ns = 0;             // of the sample's first frame
  std::vector<PixartPoint> points;  // the valid points, 0 to 4
  bool complete = false;            // both frames arrived
};

// Feed each decoded frame (its camera, which half, its points); a sample comes out when its
// second frame arrives, or, if that frame was lost, when the next sample of the camera begins.
class CameraSampleAssembler {
 public:
  // `half` is 0 for the frame of slots 0–1, 1 for slots 2–3.
  std::optional<CameraSample> add(uint16_t camera_id, int half, int64_t stamp_ns,
                                  const std::vector<PixartPoint>& points);

  // Samples still waiting for their second frame (at the end of a log).
  std::vector<CameraSample> flush();

  uint64_t incomplete_samples() const { return incomplete_; }

 private:
  std::map<uint16_t, CameraSample> pending_;
  uint64_t incomplete_ = 0;
};

}  // namespace mocap::pixart
