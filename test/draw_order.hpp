// Seeded test data drawn in one order on every compiler.
//
// The synthetic scenes of the tracking and calibration tests were first drawn in expressions
// such as `Eigen::Vector2d(noise(random), noise(random))`. C++ leaves the order of a call's
// arguments and of an operator's operands open: g++ draws the last one first, clang the first
// one first, so the two compilers made different scenes from one seed. The tests' expected
// figures were measured on g++'s scenes, and six of them fail on clang's: seeded scenes are
// single samples, and some seeds were picked for a solve that converges (see
// CalibrationRig.CeilingRigAtATenthOfAPixel). So the draws are made last first, as g++ made
// them, written out: draw_last_first() for a vector, and named values declared in reverse order
// where one expression mixes distributions.
#pragma once

#include <Eigen/Core>

namespace mocap::test {

// A vector of N values from `distribution`, coordinate N-1 drawn first and coordinate 0 last.
template <int N, class Distribution, class Engine>
Eigen::Matrix<double, N, 1> draw_last_first(Distribution& distribution, Engine& random) {
  Eigen::Matrix<double, N, 1> value;
  for (int i = N - 1; i >= 0; --i) value[i] = distribution(random);
  return value;
}

}  // namespace mocap::test
