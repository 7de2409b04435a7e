// Gaussian read noise for whole frames, as a few fixed patterns. Drawing a million normal
// samples costs about 3 ms, more than rendering everything else in a frame, so a pool of two
// frames' worth is drawn once and each pattern is a window of it at its own offset: within a
// pattern every pixel has an independent N(0, sigma) sample, and two patterns are uncorrelated.
// A frame takes pattern `frame_number % patterns()`, so consecutive frames differ; a renderer
// can then keep each pattern's background ready in 8 bits (ir_renderer.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace mocap::synthetic {

class SensorNoise {
 public:
  static constexpr int kPatterns = 16;

  // No noise at all when `sigma_dn` is 0. `seed` fixes the pool and the patterns' offsets.
  SensorNoise(int width, int height, double sigma_dn, uint64_t seed);

  bool enabled() const { return !pool_.empty(); }
  // kPatterns, or 1 (the empty pattern) without noise.
  int patterns() const { return enabled() ? kPatterns : 1; }

  // Pattern `index` (0 <= index < patterns()) as a height x width CV_32F view of the pool (no
  // copy, valid while this object lives). Empty when noise is disabled.
  cv::Mat pattern(int index) const;

 private:
  int width_, height_;
  std::vector<float> pool_;
  std::vector<size_t> offsets_;  // of each pattern in the pool
};

}  // namespace mocap::synthetic
