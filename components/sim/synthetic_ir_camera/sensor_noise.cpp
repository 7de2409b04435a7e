#include "sim/synthetic_ir_camera/sensor_noise.hpp"

#include <random>

#include <opencv2/core.hpp>

namespace mocap::synthetic {

SensorNoise::SensorNoise(int width, int height, double sigma_dn, uint64_t seed)
    : width_(width), height_(height) {
  if (sigma_dn <= 0 || width <= 0 || height <= 0) return;
  const size_t frame_size = static_cast<size_t>(width) * height;
  pool_.resize(2 * frame_size);
  cv::Mat samples(1, static_cast<int>(pool_.size()), CV_32F, pool_.data());
  cv::RNG(seed).fill(samples, cv::RNG::NORMAL, 0.0, sigma_dn);
  std::mt19937_64 random(seed);
  std::uniform_int_distribution<size_t> offset(0, pool_.size() - frame_size);
  for (int i = 0; i < kPatterns; ++i) offsets_.push_back(offset(random));
}

cv::Mat SensorNoise::pattern(int index) const {
  if (pool_.empty()) return {};
  // The view's rows are consecutive runs of the pool: a plain matrix with step = width.
  return cv::Mat(height_, width_, CV_32F,
                 const_cast<float*>(pool_.data() + offsets_.at(static_cast<size_t>(index))));
}

}  // namespace mocap::synthetic
