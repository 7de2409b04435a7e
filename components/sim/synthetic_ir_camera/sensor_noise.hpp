// Gaussian read noise for whole frames. Drawing a million normal samples costs about 3 ms, more
// than rendering everything else in a frame, so a pool of two frames' worth is drawn once and
// each frame reads a window of it that starts at a random offset: every pixel still gets an
// independent N(0, sigma) sample within the frame, and consecutive frames differ.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace mocap::synthetic {

class SensorNoise {
 public:
  // No noise at all when `sigma_dn` is 0. `seed` fixes the pool.
  SensorNoise(int width, int height, double sigma_dn, uint64_t seed);

  bool enabled() const { return !pool_.empty(); }

  // A height x width CV_32F view (no copy, valid while this object lives) of the pool at an
  // offset drawn from `random`. Empty when noise is disabled.
  cv::Mat frame(std::mt19937_64& random) const;

 private:
  int width_, height_;
  std::vector<float> pool_;
};

}  // namespace mocap::synthetic
