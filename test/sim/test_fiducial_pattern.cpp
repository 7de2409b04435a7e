// The fiducial pattern source's algorithm.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

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

// The plugin's parameter ranges keep a launch file's options usable; options built in code get
// the same checks from the pattern, which names the field.
TEST(PatternOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(PatternOptions{}.problem(), std::nullopt);
  EXPECT_EQ(PatternOptions{.count = 0}.problem(), "count: 0 is below 1");
  EXPECT_EQ(PatternOptions{.image_height = 0}.problem(), "image_height: 0 is not above 0");
  EXPECT_EQ(PatternOptions{.radius_px = -5}.problem(), "radius_px: -5 is below 0");
  EXPECT_EQ(PatternOptions{.turns_per_second = std::nan("")}.problem(),
            "turns_per_second: nan is not finite");
  try {
    fiducial_pattern({.count = 0}, 0.0);
    ADD_FAILURE() << "no points accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "PatternOptions::count: 0 is below 1");
  }
}

}  // namespace
}  // namespace mocap::demo
