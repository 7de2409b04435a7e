// The fiducial pattern source's algorithm.
#include <gtest/gtest.h>

#include <cmath>

#include "sim/fiducial_pattern_source/fiducial_pattern_source.hpp"

namespace mocap::demo {
namespace {

TEST(FiducialPattern, PointsOnATurningCircle) {
  PatternOptions options{.count = 4,
                         .image_width = 100,
                         .image_height = 50,
                         .radius_px = 10,
                         .turns_per_second = 0.25};
  auto points = fiducial_pattern(options, 0.0);
  ASSERT_EQ(points.size(), 4u);
  EXPECT_NEAR(points[0].x, 60, 1e-9);
  EXPECT_NEAR(points[0].y, 25, 1e-9);
  EXPECT_NEAR(points[1].x, 50, 1e-9);
  EXPECT_NEAR(points[1].y, 35, 1e-9);
  auto later = fiducial_pattern(options, 1.0);  // a quarter turn later
  EXPECT_NEAR(later[0].x, points[1].x, 1e-9);
  EXPECT_NEAR(later[0].y, points[1].y, 1e-9);
}

}  // namespace
}  // namespace mocap::demo
