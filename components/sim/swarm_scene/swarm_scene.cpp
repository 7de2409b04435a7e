#include "sim/swarm_scene/swarm_scene.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include <fmt/format.h>

namespace mocap::synthetic {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Minimum jerk: 0 -> 1 with no velocity or acceleration at either end.
double eased(double fraction) {
  const double t = std::clamp(fraction, 0.0, 1.0);
  return t * t * t * (10 - 15 * t + 6 * t * t);
}

// The wander's offset at `time_s`: a few sines per axis, phases from the leg's.
Eigen::Vector3d wander_offset(const SwarmLeg& leg, double time_s) {
  Eigen::Vector3d offset;
  for (int axis = 0; axis < 3; ++axis) {
    const double phase = leg.phase_rad * (1.0 + 0.37 * axis) + 1.3 * axis;
    offset[axis] = 0.6 * std::sin(leg.rate_rad_s * time_s + phase) +
                   0.4 * std::sin(1.73 * leg.rate_rad_s * time_s + 2.1 * phase);
  }
  offset.z() *= 0.5;
  return leg.radius_m * offset;
}

Eigen::Vector3d position_on(const SwarmLeg& leg, double time_s) {
  const double t = std::clamp(time_s, leg.start_s, leg.end_s);
  switch (leg.kind) {
    case SwarmLeg::Kind::Line: {
      const double length = leg.end_s - leg.start_s;
      const double fraction = length > 0 ? (t - leg.start_s) / length : 1.0;
      Eigen::Vector3d position = leg.from + eased(fraction) * (leg.to - leg.from);
      Eigen::Vector3d across = Eigen::Vector3d::UnitZ().cross(leg.to - leg.from);
      if (leg.bow_m != 0 && across.norm() > 0) {
        position += leg.bow_m * std::sin(kPi * eased(fraction)) * across.normalized();
      }
      return position;
    }
    case SwarmLeg::Kind::Circle: {
      const double angle = leg.phase_rad + leg.rate_rad_s * t;
      return leg.from + leg.radius_m * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0);
    }
    case SwarmLeg::Kind::Wander:
      return leg.from + wander_offset(leg, t) - wander_offset(leg, leg.start_s);
  }
  return leg.from;
}

SwarmSceneRobot robot_named(const std::string& prefix, size_t index,
                            const std::vector<Eigen::Vector3d>& layout) {
  SwarmSceneRobot robot;
  robot.name = fmt::format("{}{:02}", prefix, index + 1);
  robot.markers = layout;
  return robot;
}

SwarmLeg line(double start_s, double end_s, const Eigen::Vector3d& from, const Eigen::Vector3d& to,
              double bow_m = 0) {
  SwarmLeg leg;
  leg.start_s = start_s;
  leg.end_s = end_s;
  leg.from = from;
  leg.to = to;
  leg.bow_m = bow_m;
  return leg;
}

SwarmLeg wander(double start_s, double end_s, const Eigen::Vector3d& about, double radius_m,
                double rate_rad_s, double phase_rad) {
  SwarmLeg leg;
  leg.kind = SwarmLeg::Kind::Wander;
  leg.start_s = start_s;
  leg.end_s = end_s;
  leg.from = about;
  leg.radius_m = radius_m;
  leg.rate_rad_s = rate_rad_s;
  leg.phase_rad = phase_rad;
  return leg;
}

}  // namespace

Eigen::Isometry3d SwarmScene::pose(size_t robot, double time_s) const {
  const SwarmSceneRobot& r = robots.at(robot);
  if (hold_s > 0) time_s = std::max(0.0, time_s - hold_s);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  if (!r.legs.empty()) {
    auto leg = std::find_if(r.legs.rbegin(), r.legs.rend(),
                            [&](const SwarmLeg& l) { return l.start_s <= time_s; });
    pose.translation() =
        leg == r.legs.rend() ? position_on(r.legs.front(), time_s) : position_on(*leg, time_s);
  }
  const double index = static_cast<double>(robot);
  const double roll = r.tilt_rad * std::sin(1.3 * time_s + index);
  const double pitch = r.tilt_rad * std::sin(0.9 * time_s + 2 * index);
  pose.linear() =
      (Eigen::AngleAxisd(r.yaw_rad + r.yaw_rate_rad_s * time_s, Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()) *
       Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()))
          .toRotationMatrix();
  return pose;
}

std::vector<Eigen::Vector3d> SwarmScene::markers(double time_s) const {
  std::vector<Eigen::Vector3d> all;
  for (size_t r = 0; r < robots.size(); ++r) {
    const Eigen::Isometry3d at = pose(r, time_s);
    for (const Eigen::Vector3d& marker : robots[r].markers) all.push_back(at * marker);
  }
  return all;
}

SwarmScene SwarmScene::with(const SwarmScene& other) const {
  SwarmScene both = *this;
  both.duration_s = std::max(duration_s, other.duration_s);
  both.hold_s = std::max(hold_s, other.hold_s);
  both.occluders.insert(both.occluders.end(), other.occluders.begin(), other.occluders.end());
  for (SwarmSceneRobot robot : other.robots) {
    const std::string name = robot.name;
    for (int n = 2; std::any_of(both.robots.begin(), both.robots.end(),
                                [&](const SwarmSceneRobot& r) { return r.name == robot.name; });
         ++n) {
      robot.name = fmt::format("{}_{}", name, n);
    }
    both.robots.push_back(std::move(robot));
  }
  return both;
}

SwarmScene SwarmScene::shifted(const Eigen::Vector3d& offset) const {
  SwarmScene moved = *this;
  for (SwarmSceneRobot& robot : moved.robots) {
    for (SwarmLeg& leg : robot.legs) {
      leg.from += offset;
      leg.to += offset;
    }
  }
  for (OccludingSphere& occluder : moved.occluders) occluder.centre += offset;
  return moved;
}

std::vector<Eigen::Vector3d> marker_deck_layout() {
  // Four markers on posts of different heights, no two distances alike.
  return {{0.000, 0.021, 0.012},
          {0.019, -0.008, 0.018},
          {-0.016, -0.013, 0.014},
          {0.004, 0.001, 0.034}};
}

std::vector<Eigen::Vector3d> single_marker_layout() { return {Eigen::Vector3d::Zero()}; }

SwarmScene takeoff_grid(const std::vector<Eigen::Vector3d>& layout, int rows, int columns,
                        double spacing_m, double height_m, double climb_s, double duration_s,
                        const std::string& prefix) {
  SwarmScene scene;
  scene.duration_s = duration_s;
  for (int row = 0; row < rows; ++row) {
    for (int column = 0; column < columns; ++column) {
      SwarmSceneRobot robot = robot_named(prefix, scene.robots.size(), layout);
      const Eigen::Vector3d ground((column - (columns - 1) / 2.0) * spacing_m,
                                   (row - (rows - 1) / 2.0) * spacing_m, 0);
      const Eigen::Vector3d up = ground + Eigen::Vector3d(0, 0, height_m);
      constexpr double lift_s = 0.5;
      robot.legs.push_back(line(lift_s, lift_s + climb_s, ground, up));
      robot.legs.push_back(wander(lift_s + climb_s, duration_s, up, 0.03, 1.1,
                                  static_cast<double>(scene.robots.size())));
      robot.yaw_rad = 0.3 * static_cast<double>(scene.robots.size());
      robot.yaw_rate_rad_s = 0.2;
      robot.tilt_rad = 0.05;
      scene.robots.push_back(std::move(robot));
    }
  }
  return scene;
}

SwarmScene formation_circle(const std::vector<Eigen::Vector3d>& layout, int count, double radius_m,
                            double height_m, double rate_rad_s, double duration_s,
                            const std::string& prefix) {
  SwarmScene scene;
  scene.duration_s = duration_s;
  for (int k = 0; k < count; ++k) {
    SwarmSceneRobot robot = robot_named(prefix, static_cast<size_t>(k), layout);
    SwarmLeg leg;
    leg.kind = SwarmLeg::Kind::Circle;
    leg.start_s = 0;
    leg.end_s = duration_s;
    leg.from = Eigen::Vector3d(0, 0, height_m);
    leg.radius_m = radius_m;
    leg.rate_rad_s = rate_rad_s;
    leg.phase_rad = 2 * kPi * k / count;
    robot.legs.push_back(leg);
    robot.yaw_rad = leg.phase_rad + kPi / 2;
    robot.yaw_rate_rad_s = rate_rad_s;
    robot.tilt_rad = 0.1;
    scene.robots.push_back(std::move(robot));
  }
  return scene;
}

SwarmScene crossing_pairs(const std::vector<Eigen::Vector3d>& layout, int pairs,
                          double separation_m, double speed_mps, double pair_spacing_m,
                          double height_m, double duration_s, const std::string& prefix) {
  constexpr double kHalfLength_m = 0.6, kPause_s = 0.5;
  // The eased flight averages `speed_mps` over its length.
  const double pass_s = 2 * kHalfLength_m / speed_mps;
  SwarmScene scene;
  scene.duration_s = duration_s;
  for (int p = 0; p < pairs; ++p) {
    const double y = (p - (pairs - 1) / 2.0) * pair_spacing_m;
    for (int side = 0; side < 2; ++side) {
      SwarmSceneRobot robot = robot_named(prefix, scene.robots.size(), layout);
      const double lane = y + (side == 0 ? -separation_m / 2 : separation_m / 2);
      Eigen::Vector3d here(side == 0 ? -kHalfLength_m : kHalfLength_m, lane, height_m);
      Eigen::Vector3d there(-here.x(), lane, height_m);
      for (double start = kPause_s; start < duration_s; start += pass_s + kPause_s) {
        robot.legs.push_back(line(start, start + pass_s, here, there));
        std::swap(here, there);
      }
      robot.yaw_rad = side == 0 ? 0 : kPi;
      robot.tilt_rad = 0.08;
      scene.robots.push_back(std::move(robot));
    }
  }
  return scene;
}

SwarmScene place_exchange(const std::vector<Eigen::Vector3d>& layout, const Eigen::Vector3d& centre,
                          double distance_m, double separation_m, double over_s, double period_s,
                          double duration_s, const std::string& prefix) {
  SwarmScene scene;
  scene.duration_s = duration_s;
  for (int side = 0; side < 2; ++side) {
    SwarmSceneRobot robot = robot_named(prefix, scene.robots.size(), layout);
    Eigen::Vector3d here = centre + Eigen::Vector3d((side == 0 ? -0.5 : 0.5) * distance_m, 0, 0);
    Eigen::Vector3d there = 2 * centre - here;
    for (double start = (period_s - over_s) / 2; start < duration_s; start += period_s) {
      // Each bows to its own left: they pass `separation_m` apart.
      robot.legs.push_back(line(start, start + over_s, here, there, separation_m / 2));
      std::swap(here, there);
    }
    robot.yaw_rad = 1.0 + side;
    robot.yaw_rate_rad_s = 0.3;
    robot.tilt_rad = 0.08;
    scene.robots.push_back(std::move(robot));
  }
  return scene;
}

SwarmScene random_flight(const std::vector<Eigen::Vector3d>& layout, int count, double extent_m,
                         double height_m, double min_separation_m, double duration_s, uint64_t seed,
                         const std::string& prefix) {
  double size_m = 0;
  for (const Eigen::Vector3d& a : layout) {
    for (const Eigen::Vector3d& b : layout) size_m = std::max(size_m, (a - b).norm());
  }
  const int columns = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(count))));
  const double cell_m = extent_m / columns;
  // Each wanders within its cell: neighbours' markers stay `min_separation_m` apart. The
  // wander's offset reaches at most its radius per axis from where it started (twice from the
  // middle), in x and y.
  const double radius_m = (cell_m - min_separation_m - size_m) / 4;
  if (!(radius_m > 0)) {
    throw std::invalid_argument(
        fmt::format("random_flight: {} robots in {} m leave no room to move {} m apart", count,
                    extent_m, min_separation_m));
  }
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> phase(0, 2 * kPi), rate(0.6, 1.4), yaw(-kPi, kPi);
  SwarmScene scene;
  scene.duration_s = duration_s;
  for (int k = 0; k < count; ++k) {
    SwarmSceneRobot robot = robot_named(prefix, static_cast<size_t>(k), layout);
    const Eigen::Vector3d home((k % columns - (columns - 1) / 2.0) * cell_m,
                               (k / columns - (columns - 1) / 2.0) * cell_m, height_m);
    const double r = rate(random);
    const double p = phase(random);
    robot.legs.push_back(wander(0, duration_s, home, radius_m, r, p));
    robot.yaw_rad = yaw(random);
    robot.yaw_rate_rad_s = 0.5 * (rate(random) - 1);
    robot.tilt_rad = 0.1;
    scene.robots.push_back(std::move(robot));
  }
  return scene;
}

}  // namespace mocap::synthetic
