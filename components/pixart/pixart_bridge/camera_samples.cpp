#include "pixart/pixart_bridge/camera_samples.hpp"

namespace mocap::pixart {

std::optional<CameraSample> CameraSampleAssembler::add(uint16_t camera_id, int half,
                                                       int64_t stamp_ns,
                                                       const std::vector<PixartPoint>& points) {
  std::optional<CameraSample> out;
  auto pending = pending_.find(camera_id);
  if (half == 0) {
    // A new sample begins; one still pending lost its second frame.
    if (pending != pending_.end()) {
      out = std::move(pending->second);
      ++incomplete_;
      pending_.erase(pending);
    }
    pending_[camera_id] = CameraSample{camera_id, stamp_ns, points, false};
    return out;
  }
  if (pending == pending_.end()) {
    // The first frame was lost: what arrived is a sample of its own.
    ++incomplete_;
    return CameraSample{camera_id, stamp_ns, points, false};
  }
  CameraSample sample = std::move(pending->second);
  pending_.erase(pending);
  sample.points.insert(sample.points.end(), points.begin(), points.end());
  sample.complete = true;
  return sample;
}

std::vector<CameraSample> CameraSampleAssembler::flush() {
  std::vector<CameraSample> out;
  for (auto& [camera, sample] : pending_) {
    out.push_back(std::move(sample));
    ++incomplete_;
  }
  pending_.clear();
  return out;
}

}  // namespace mocap::pixart
