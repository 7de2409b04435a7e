// Swarms in the volume: identical quadrotors told apart by their tracks, single-marker robots,
// each from the marker cloud of eight cameras sending centroids at 240 Hz with 0.05 px of
// noise. Short scenes of the swarm issue's kinds, each held to its targets: no identity swap,
// 99.9 % of robot-frames tracked, position error median 0.1 mm, orientation 0.2 degrees.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "sim/swarm_scene/swarm_scene_file.hpp"
#include "test/test_support.hpp"
#include "test/volume/swarm_rig.hpp"
#include "volume/swarm/swarm_database.hpp"
#include "volume/swarm/swarm_tracker.hpp"

namespace mocap::volume {
namespace {

using synthetic::SwarmScene;

constexpr double kRate_hz = 240;

test::SwarmRig eight_cameras(uint64_t seed = 1) {
  synthetic::CentroidCameraOptions options;
  options.noise_px = 0.05;
  return test::SwarmRig((mocap::test::source_dir() / "config").string(), 8, options, seed);
}

// Why a scene file's text is refused ("scene.yaml:LINE: ..."); empty, and a failure, when it is
// accepted.
std::string refusal_of(const std::string& text) {
  try {
    synthetic::parse_swarm_scene(text, "scene.yaml");
  } catch (const synthetic::SwarmSceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "accepted:\n" << text;
  return "";
}

// The swarm issue's targets.
void expect_targets(const test::SwarmFigures& figures, bool oriented) {
  fmt::print(
      "{} robot-frames, {} tracked ({:.3f} %), {} identity swaps, {} wrong poses, position median "
      "{:.4f} mm, orientation median {:.4f} deg\n",
      figures.robot_frames, figures.tracked, 100 * figures.tracked_fraction(),
      figures.identity_swaps, figures.wrong_poses,
      1e3 * test::SwarmFigures::median(figures.position_errors_m),
      test::SwarmFigures::median(figures.orientation_errors_deg));
  EXPECT_EQ(figures.identity_swaps, 0);
  EXPECT_EQ(figures.wrong_poses, 0);
  EXPECT_GE(figures.tracked_fraction(), 0.999)
      << figures.tracked << " of " << figures.robot_frames << " robot-frames";
  EXPECT_LE(test::SwarmFigures::median(figures.position_errors_m), 0.1e-3);
  if (oriented) {
    EXPECT_LE(test::SwarmFigures::median(figures.orientation_errors_deg), 0.2);
  }
}

TEST(SwarmDatabase, ReadsLayoutsAndRobots) {
  const SwarmDatabase swarm = parse_swarm(R"(
layouts:
  - name: deck
    markers: [[0, 0.021, 0.012], [0.019, -0.008, 0.018], [-0.016, -0.013, 0.014], [0.004, 0.001, 0.034]]
    top_speed_mps: 2
  - name: single
    markers: [[0, 0, 0]]
robots:
  - {name: cf01, layout: deck, initial_position: [-1, -1, 0]}
  - {name: cf02, layout: deck, initial_position: [-0.7, -1, 0]}
  - {name: rover, layout: single, initial_position: [0.5, 0, 0.1]}
)",
                                          "robots.yaml", 0.002);
  ASSERT_EQ(swarm.layouts.size(), 2u);
  EXPECT_EQ(swarm.layouts[0].top_speed_mps, 2);
  EXPECT_EQ(swarm.layouts[1].top_speed_mps, 3);
  ASSERT_EQ(swarm.robots.size(), 3u);
  EXPECT_EQ(swarm.robots[1].name, "cf02");
  EXPECT_EQ(swarm.robots[2].layout, 1u);
  EXPECT_EQ(swarm.robots[1].initial_position, Eigen::Vector3d(-0.7, -1, 0));
}

TEST(SwarmDatabase, RefusesWhatCannotBeToldApartWithOneLineNamingIt) {
  const std::string deck =
      "layouts:\n"
      "  - name: deck\n"
      "    markers: [[0, 0.021, 0.012], [0.019, -0.008, 0.018], [-0.016, -0.013, 0.014], "
      "[0.004, 0.001, 0.034]]\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"layouts:\n  - {name: pair, markers: [[0, 0, 0], [0.05, 0, 0]]}\n",
       "robots.yaml:2: layout 'pair' needs 1 marker, or 3 or more, not a list of 2"},
      {"layouts:\n  - {name: square, markers: [[0, 0, 0], [0.05, 0, 0], [0.05, 0.05, 0], "
       "[0, 0.05, 0]]}\n",
       "robots.yaml:2: layout 'square' is symmetric"},
      {deck + "robots:\n  - {name: a, layout: deck, initial_position: [0, 0, 0]}\n"
              "  - {name: b, layout: deck, initial_position: [0.03, 0, 0]}\n",
       "robots.yaml:6: robots 'a' and 'b' (line 5) of layout 'deck' start 0.030 m apart, closer "
       "than the layout's size (0.038 m): which is which could not be told"},
      {deck + "robots:\n  - {name: a, layout: plate, initial_position: [0, 0, 0]}\n",
       "robots.yaml:5: robot 'a': no layout 'plate' in the file"},
      {deck + "robots:\n  - {name: a, layout: deck, initial_position: [0, 0, 0]}\n"
              "  - {name: a, layout: deck, initial_position: [1, 0, 0]}\n",
       "robots.yaml:6: robot 'a' is declared twice"},
  };
  for (const auto& [text, expected] : cases) {
    try {
      parse_swarm(text, "robots.yaml", 0.002);
      ADD_FAILURE() << "accepted:\n" << text;
    } catch (const RigidBodyError& e) {
      EXPECT_EQ(std::string(e.what()).substr(0, expected.size()), expected) << e.what();
    }
  }
}

// The demo's robots file is the one its scene makes: the names and the starts cannot drift apart.
TEST(SwarmScene, TheDemosRobotsFileIsTheOneItsSceneMakes) {
  const std::string config = (mocap::test::source_dir() / "config" / "swarm").string();
  const synthetic::SwarmScene scene = synthetic::load_swarm_scene(config + "/scene.yaml");
  ASSERT_EQ(scene.robots.size(), 100u);
  const SwarmDatabase made = parse_swarm(synthetic::robots_file_of(scene), "made",
                                         SwarmTrackerOptions{}.layout_tolerance_m);
  const SwarmDatabase shipped =
      load_swarm(config + "/robots.yaml", SwarmTrackerOptions{}.layout_tolerance_m);
  ASSERT_EQ(shipped.robots.size(), made.robots.size());
  for (size_t r = 0; r < made.robots.size(); ++r) {
    EXPECT_EQ(shipped.robots[r].name, made.robots[r].name);
    EXPECT_EQ(shipped.layouts[shipped.robots[r].layout].markers,
              made.layouts[made.robots[r].layout].markers);
    EXPECT_LT((shipped.robots[r].initial_position - scene.pose(r, 0).translation()).norm(), 1e-6);
  }
}

// A swarm waits where it starts while its tracker comes up: with `hold_s`, every robot stays
// at its pose of time 0 until then, and flies afterwards as the scene without the hold does.
TEST(SwarmScene, AHoldKeepsEveryRobotWhereItsFlightStarts) {
  const std::string flights =
      "layouts:\n  - {name: deck, markers: [[0, 0.02, 0], [0.02, 0, 0], [0, 0, 0.03]]}\n"
      "groups:\n  - {flight: crossing_pairs, layout: deck, pairs: 1, separation_m: 0.05,"
      " speed_mps: 1, pair_spacing_m: 0.5, height_m: 1}\n";
  const SwarmScene held = synthetic::parse_swarm_scene("hold_s: 2\n" + flights, "scene.yaml");
  const SwarmScene flying = synthetic::parse_swarm_scene(flights, "scene.yaml");
  ASSERT_EQ(held.robots.size(), 2u);
  for (size_t r = 0; r < held.robots.size(); ++r) {
    EXPECT_TRUE(held.pose(r, 1.9).isApprox(flying.pose(r, 0), 1e-12));
    EXPECT_TRUE(held.pose(r, 3.2).isApprox(flying.pose(r, 1.2), 1e-12));
  }
  // Without the hold, 1.2 s in, the first robot has flown more than half way to the other end.
  EXPECT_GT((flying.pose(0, 1.2).translation() - flying.pose(0, 0).translation()).norm(), 0.6);
  const std::string negative = refusal_of("hold_s: -1\n" + flights);
  EXPECT_NE(negative.find("scene.yaml:1:"), std::string::npos) << negative;
  EXPECT_NE(negative.find("hold_s"), std::string::npos) << negative;
}

// Occluders stand where the file puts them; one without its radius is refused on its line.
TEST(SwarmScene, OccludersStandWhereTheFileSays) {
  const std::string flights =
      "layouts:\n  - {name: single, markers: [[0, 0, 0]]}\n"
      "groups:\n  - {flight: formation_circle, layout: single, count: 3, radius_m: 1,"
      " height_m: 1, rate_rad_s: 0.5}\n";
  const SwarmScene pillared = synthetic::parse_swarm_scene(
      "occluders:\n  - {centre: [0, 0.5, 1], radius_m: 0.3}\n" + flights, "scene.yaml");
  ASSERT_EQ(pillared.occluders.size(), 1u);
  EXPECT_EQ(pillared.occluders[0].centre, Eigen::Vector3d(0, 0.5, 1));
  EXPECT_EQ(pillared.occluders[0].radius_m, 0.3);
  EXPECT_EQ(pillared.shifted(Eigen::Vector3d(1, 0, 0)).occluders[0].centre,
            Eigen::Vector3d(1, 0.5, 1));
  const std::string no_radius = refusal_of("occluders:\n  - {centre: [0, 0.5, 1]}\n" + flights);
  EXPECT_NE(no_radius.find("scene.yaml:2:"), std::string::npos) << no_radius;
  EXPECT_NE(no_radius.find("radius_m"), std::string::npos) << no_radius;
}

TEST(SwarmScene, AFileThatCannotBeFlownIsRefusedWithOneLineNamingIt) {
  const std::string layouts = "layouts:\n  - {name: single, markers: [[0, 0, 0]]}\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {layouts + "groups:\n  - {flight: loop, layout: single, count: 3}\n",
       "scene.yaml:4: unknown flight 'loop'"},
      {layouts + "groups:\n  - {flight: random_flight, layout: dot, count: 3}\n",
       "scene.yaml:4: no layout 'dot' in the file"},
      {layouts + "groups:\n  - {flight: random_flight, layout: single, count: 100, extent_m: 1,"
                 " height_m: 1, min_separation_m: 0.2}\n",
       "scene.yaml:4: random_flight: 100 robots in 1 m leave no room to move 0.2 m apart"},
      {layouts + "groups:\n  - {flight: formation_circle, layout: single, count: 3, radius_m: 1,"
                 " height_m: 1, rate_rad_s: 0.5, speed: 3}\n",
       "scene.yaml:4:"},
      {layouts + "groups:\n  - {flight: formation_circle, layout: single, count: 3, radius_m: 1,"
                 " height_m: 1, rate_rad_s: 0.5}\n  - {flight: formation_circle, layout: single,"
                 " count: 3, radius_m: 2, height_m: 1, rate_rad_s: 0.5}\n",
       "scene.yaml:5: robot 'robot_01' is named twice: give the group its own prefix"},
  };
  for (const auto& [text, expected] : cases) {
    const std::string refusal = refusal_of(text);
    EXPECT_EQ(refusal.substr(0, expected.size()), expected) << refusal;
  }
}

TEST(SwarmTracker, IdenticalQuadrotorsCrossingFiveCentimetresApartKeepTheirNames) {
  test::SwarmRig rig = eight_cameras();
  const SwarmScene scene =
      synthetic::crossing_pairs(synthetic::marker_deck_layout(), 4, 0.05, 1.0, 0.5, 1.0, 3.0);
  const test::SwarmFigures figures = test::track_swarm(scene, rig, kRate_hz, scene.duration_s);
  expect_targets(figures, true);
}

TEST(SwarmTracker, TwoIdenticalQuadrotorsExchangePlaces) {
  test::SwarmRig rig = eight_cameras(2);
  const SwarmScene scene = synthetic::place_exchange(
      synthetic::marker_deck_layout(), Eigen::Vector3d(0, 0, 1), 0.8, 0.05, 1.0, 1.5, 3.0);
  const test::SwarmFigures figures = test::track_swarm(scene, rig, kRate_hz, scene.duration_s);
  expect_targets(figures, true);
}

TEST(SwarmTracker, FiftyQuadrotorsTakeOffFromAGrid) {
  test::SwarmRig rig = eight_cameras(3);
  const SwarmScene scene =
      synthetic::takeoff_grid(synthetic::marker_deck_layout(), 5, 10, 0.3, 1.0, 1.0, 3.0);
  const test::SwarmFigures figures = test::track_swarm(scene, rig, kRate_hz, scene.duration_s);
  expect_targets(figures, true);
}

TEST(SwarmTracker, AHundredSingleMarkerRobotsInRandomFlight) {
  test::SwarmRig rig = eight_cameras(4);
  const SwarmScene scene =
      synthetic::random_flight(synthetic::single_marker_layout(), 100, 3.0, 1.0, 0.1, 2.0, 11);
  const test::SwarmFigures figures = test::track_swarm(scene, rig, kRate_hz, scene.duration_s);
  expect_targets(figures, false);
}

TEST(SwarmTracker, AMixedSwarmOfFiftyQuadrotorsAndFiftySingleMarkerRobots) {
  test::SwarmRig rig = eight_cameras(5);
  const SwarmScene scene =
      synthetic::random_flight(synthetic::marker_deck_layout(), 50, 3.0, 1.3, 0.1, 2.0, 12, "cf")
          .with(synthetic::random_flight(synthetic::single_marker_layout(), 50, 3.0, 0.6, 0.1, 2.0,
                                         13, "rover"));
  const test::SwarmFigures figures = test::track_swarm(scene, rig, kRate_hz, scene.duration_s);
  expect_targets(figures, false);
  EXPECT_LE(test::SwarmFigures::median(figures.orientation_errors_deg), 0.2);
}

// A pillar's stretch (an occluder of the scene file) stands beside the lanes of a crossing pair:
// as the pair passes it, cameras behind it lose sight of them, and the pair is tracked through.
TEST(SwarmTracker, APairPassingAPillarIsTrackedThroughWhatItHides) {
  SwarmScene scene =
      synthetic::crossing_pairs(synthetic::marker_deck_layout(), 1, 0.05, 1.0, 0.5, 1.0, 3.0);
  scene.occluders.push_back({Eigen::Vector3d(0, 0.5, 1.0), 0.3});
  test::SwarmRig rig = eight_cameras(13);
  const auto centroids = [](const std::vector<CameraDetections>& cameras) {
    size_t count = 0;
    for (const CameraDetections& camera : cameras) count += camera.pixels.size();
    return count;
  };
  size_t hidden = 0;
  for (double time_s = 0; time_s < scene.duration_s; time_s += 0.05) {
    hidden += centroids(rig.frame(scene.markers(time_s))) - centroids(rig.frame(scene, time_s));
  }
  EXPECT_GT(hidden, 0u) << "the pillar hid nothing";
  const test::SwarmFigures figures = test::track_swarm(scene, rig, kRate_hz, scene.duration_s);
  expect_targets(figures, true);
}

// Quadrotors on the floor among robots of one marker: from scratch, some are seen by three
// markers of a nearly isosceles triangle, which a half turn relabels; each is found upright,
// not turned over (the mixed take-off once put one 3 cm and 180 degrees off for the whole run).
// Names and poses only: the accuracy targets are the 60 s scenes' (swarm_bench: 0.096 mm for
// this one), and a quarter of these 2 s is on the floor, where the cameras see the markers low.
TEST(SwarmTracker, AMixedSwarmTakesOffWithEveryQuadrotorUpright) {
  test::SwarmRig rig = eight_cameras(8);
  const SwarmScene scene =
      synthetic::takeoff_grid(synthetic::marker_deck_layout(), 5, 10, 0.3, 1.0, 0.5, 2.0, "cf")
          .with(synthetic::takeoff_grid(synthetic::single_marker_layout(), 5, 10, 0.3, 0.6, 0.5,
                                        2.0, "rover")
                    .shifted(Eigen::Vector3d(0.15, 0.15, 0)));
  const test::SwarmFigures figures = test::track_swarm(scene, rig, kRate_hz, scene.duration_s);
  EXPECT_EQ(figures.wrong_poses, 0);
  EXPECT_EQ(figures.identity_swaps, 0);
  EXPECT_GE(figures.tracked_fraction(), 0.999);
}

// Two identical robots side by side; one vanishes (carried under a cloth) for 0.3 s while the
// other flies past where it was.
TEST(SwarmTracker, ALostRobotIsFoundAgainWithoutTakingAnothersMarkers) {
  SwarmScene scene = synthetic::place_exchange(synthetic::marker_deck_layout(),
                                               Eigen::Vector3d(0, 0, 1), 0.4, 0.05, 0.5, 2.0, 2.0);
  test::SwarmRig rig = eight_cameras(6);
  MarkerCloudTracker cloud;
  SwarmTracker swarm(test::swarm_database_of(scene));
  int lost_frames = 0, posed_after = 0;
  for (int f = 0; f < 480; ++f) {
    const double time_s = f / kRate_hz;
    std::vector<Eigen::Vector3d> markers = scene.markers(time_s);
    const bool hidden = time_s >= 0.5 && time_s < 0.8;
    if (hidden) markers.erase(markers.begin(), markers.begin() + 4);  // robot 0's
    const auto stamp_ns = static_cast<int64_t>(time_s * 1e9);
    for (const SwarmRobotPose& pose :
         swarm.track(stamp_ns, cloud.track(stamp_ns, rig.frame(markers)))) {
      const Eigen::Vector3d own = scene.pose(pose.robot, time_s).translation();
      const Eigen::Vector3d other = scene.pose(1 - pose.robot, time_s).translation();
      EXPECT_LT((pose.world_from_body.translation() - own).norm(), 1e-3)
          << swarm.swarm().robots[pose.robot].name << " at " << time_s << " s";
      EXPECT_GT((pose.world_from_body.translation() - other).norm(), 0.01);
      if (pose.robot == 0 && hidden) ADD_FAILURE() << "robot 0 posed while hidden";
      if (pose.robot == 0 && time_s >= 0.8) ++posed_after;
    }
    if (hidden) lost_frames += swarm.counts().searching;
  }
  EXPECT_GT(lost_frames, 0);
  // Found again in its first frame back.
  EXPECT_EQ(posed_after, 480 - static_cast<int>(0.8 * kRate_hz));
}

// Twenty identical robots on the floor 0.2 m apart, all hidden for 0.3 s: every one is lost,
// and each search has grown over the whole grid when they come back. Each is found again, as
// itself, in its first frame back.
TEST(SwarmTracker, AGridLostAtOnceIsFoundAgainRobotByRobot) {
  const SwarmScene scene =
      synthetic::takeoff_grid(synthetic::marker_deck_layout(), 4, 5, 0.2, 1.0, 1.0, 2.0);
  test::SwarmRig rig = eight_cameras(11);
  MarkerCloudTracker cloud;
  SwarmTracker swarm(test::swarm_database_of(scene));
  int posed_back = 0;
  for (int f = 0; f < 240; ++f) {
    const double time_s = f / kRate_hz;  // the grid rises after 0.5 s: all at rest
    const bool hidden = time_s >= 0.1 && time_s < 0.4;
    std::vector<Eigen::Vector3d> markers = scene.markers(time_s);
    if (hidden) markers.clear();
    const auto stamp_ns = static_cast<int64_t>(time_s * 1e9);
    const std::vector<SwarmRobotPose> poses =
        swarm.track(stamp_ns, cloud.track(stamp_ns, rig.frame(markers)));
    for (const SwarmRobotPose& pose : poses) {
      EXPECT_LT((pose.world_from_body.translation() - scene.pose(pose.robot, time_s).translation())
                    .norm(),
                1e-3)
          << swarm.swarm().robots[pose.robot].name << " at " << time_s << " s";
    }
    if (time_s >= 0.4 && time_s < 0.5) posed_back += static_cast<int>(poses.size());
  }
  // Every robot in every frame back but the first (the cloud needs a frame to start its
  // markers' tracks from three cameras or more: they start in it).
  EXPECT_EQ(posed_back, 20 * static_cast<int>(std::lround(0.1 * kRate_hz)));
}

// Robot A hovers, and is hidden from 0.55 s (lost: its search grows at its top speed). Robot B,
// not found yet, flies to where it starts and stops there at 1 s: while it slows down within
// its start radius, it may not be found (not at rest), and A's search reaches it. B is nearer
// where it is looked for than A is: nobody takes it, and B is found once it is at rest.
TEST(SwarmTracker, ARobotNotAtRestAtItsStartIsNotTakenByALostOne) {
  SwarmScene scene;
  scene.duration_s = 1.5;
  for (const auto& [name, from, to] :
       {std::tuple{"a", Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, 1)},
        std::tuple{"b", Eigen::Vector3d(0.55, 0, 1), Eigen::Vector3d(0.25, 0, 1)}}) {
    synthetic::SwarmSceneRobot robot;
    robot.name = name;
    robot.markers = synthetic::marker_deck_layout();
    robot.legs.push_back({.start_s = 0, .end_s = 1, .from = from, .to = to});
    scene.robots.push_back(std::move(robot));
  }
  SwarmDatabase database = test::swarm_database_of(scene);
  database.robots[1].initial_position = Eigen::Vector3d(0.25, 0, 1);
  test::SwarmRig rig = eight_cameras(12);
  MarkerCloudTracker cloud;
  SwarmTracker swarm(database);
  double b_found_s = -1;
  for (int f = 0; f < 360; ++f) {
    const double time_s = f / kRate_hz;
    std::vector<Eigen::Vector3d> markers = scene.markers(time_s);
    if (time_s >= 0.55) markers.erase(markers.begin(), markers.begin() + 4);  // a's
    const auto stamp_ns = static_cast<int64_t>(time_s * 1e9);
    for (const SwarmRobotPose& pose :
         swarm.track(stamp_ns, cloud.track(stamp_ns, rig.frame(markers)))) {
      EXPECT_LT((pose.world_from_body.translation() - scene.pose(pose.robot, time_s).translation())
                    .norm(),
                1e-3)
          << database.robots[pose.robot].name << " at " << time_s << " s";
      if (pose.robot == 1 && b_found_s < 0) b_found_s = time_s;
    }
  }
  // B slows below the start speed about 0.15 s before it stops.
  EXPECT_GT(b_found_s, 0.7);
  EXPECT_LT(b_found_s, 1.05);
}

// Bodies and robots in one volume: a rigid body's markers (claimed by the body's tracker, as
// volume_fusion labels them) are nobody's robot, even a robot of the same layout looked for
// right where the body stands.
TEST(SwarmTracker, MarkersABodyClaimsAreNotTakenForARobot) {
  const SwarmScene scene =
      synthetic::crossing_pairs(synthetic::marker_deck_layout(), 1, 0.05, 1.0, 0.5, 1.0, 1.0);
  SwarmDatabase one_robot = test::swarm_database_of(scene);
  one_robot.robots.erase(one_robot.robots.begin() + 1);  // robot 0 is looked for; 1 is a body
  one_robot.robots[0].initial_position = scene.pose(1, 0).translation();
  test::SwarmRig rig = eight_cameras(14);
  MarkerCloudTracker cloud;
  SwarmTracker swarm(one_robot);
  int claimed_frames = 0;
  for (int f = 0; f < 240; ++f) {
    const double time_s = f / kRate_hz;
    const auto stamp_ns = static_cast<int64_t>(time_s * 1e9);
    const std::vector<CloudMarker> markers = cloud.track(stamp_ns, rig.frame(scene, time_s));
    const Eigen::Isometry3d body = scene.pose(1, time_s);
    std::vector<char> claimed(markers.size(), 0);
    for (size_t m = 0; m < markers.size(); ++m) {
      for (const Eigen::Vector3d& marker : scene.robots[1].markers) {
        if ((markers[m].position - body * marker).norm() < 0.005) claimed[m] = 1;
      }
    }
    claimed_frames += std::count(claimed.begin(), claimed.end(), 1) >= 3 ? 1 : 0;
    for (const SwarmRobotPose& pose : swarm.track(stamp_ns, markers, claimed)) {
      EXPECT_GT((pose.world_from_body.translation() - body.translation()).norm(), 0.01)
          << "the robot was posed on the body's markers at " << time_s << " s";
    }
  }
  EXPECT_GT(claimed_frames, 200);
  EXPECT_EQ(swarm.counts().searching, 1);
}

TEST(SwarmTracker, ARobotCarriedAwayIsFoundWhereItIsReseeded) {
  SwarmScene scene =
      synthetic::random_flight(synthetic::marker_deck_layout(), 4, 2.0, 1.0, 0.1, 2.0, 21);
  test::SwarmRig rig = eight_cameras(7);
  MarkerCloudTracker cloud;
  SwarmTracker swarm(test::swarm_database_of(scene));
  const Eigen::Vector3d carried(0, 1.5, 0.8);  // beyond the widest search from where it was
  bool reseeded = false;
  int posed_carried = 0;
  for (int f = 0; f < 240; ++f) {
    const double time_s = f / kRate_hz;
    std::vector<Eigen::Vector3d> markers = scene.markers(time_s);
    const bool away = time_s >= 0.25;
    if (away) {
      const Eigen::Isometry3d at = scene.pose(0, time_s);
      for (int m = 0; m < 4; ++m) markers[m] = carried + at.linear() * scene.robots[0].markers[m];
    }
    if (time_s >= 0.6 && !reseeded) reseeded = swarm.reseed(scene.robots[0].name, carried);
    const auto stamp_ns = static_cast<int64_t>(time_s * 1e9);
    for (const SwarmRobotPose& pose :
         swarm.track(stamp_ns, cloud.track(stamp_ns, rig.frame(markers)))) {
      if (pose.robot != 0 || !away) continue;
      EXPECT_GE(time_s, 0.6) << "found 1.5 m away before it was re-seeded there";
      EXPECT_LT((pose.world_from_body.translation() - carried).norm(), 1e-3);
      ++posed_carried;
    }
  }
  EXPECT_TRUE(reseeded);
  EXPECT_EQ(posed_carried, 240 - static_cast<int>(0.6 * kRate_hz));
  EXPECT_FALSE(swarm.reseed("nobody", carried));
}

// A robot flying past where another starts, before that one is found (a swarm in the air when
// the tracker comes up), is not taken for it: a robot is found at its start only at rest.
TEST(SwarmTracker, ARobotFlyingPastAnothersStartIsNotTakenForIt) {
  const SwarmScene scene =
      synthetic::random_flight(synthetic::marker_deck_layout(), 1, 2.0, 1.0, 0.1, 2.0, 31);
  // Where the robot flies fastest, a second in.
  const auto speed_at = [&](double time_s) {
    return (scene.pose(0, time_s + 0.01).translation() - scene.pose(0, time_s).translation())
               .norm() /
           0.01;
  };
  double passing_s = 0.5;
  for (double time_s = 0.5; time_s <= 1.5; time_s += 0.05) {
    if (speed_at(time_s) > speed_at(passing_s)) passing_s = time_s;
  }
  const double speed = speed_at(passing_s);
  const Eigen::Vector3d passing = scene.pose(0, passing_s).translation();
  ASSERT_GT(speed, 1.2 * SwarmTrackerOptions{}.start_speed_mps) << "the scene's robot flies slowly";
  SwarmDatabase waiting = test::swarm_database_of(scene);
  waiting.robots[0].name = "waiting";
  waiting.robots[0].initial_position = passing;
  test::SwarmRig rig = eight_cameras(10);
  MarkerCloudTracker cloud;
  SwarmTracker swarm(waiting);
  int posed = 0;
  for (int f = 0; f < 480; ++f) {
    const auto stamp_ns = static_cast<int64_t>(f / kRate_hz * 1e9);
    posed += static_cast<int>(
        swarm.track(stamp_ns, cloud.track(stamp_ns, rig.frame(scene, f / kRate_hz))).size());
  }
  EXPECT_EQ(posed, 0) << "the robot flying at " << speed << " m/s was taken for 'waiting'";
  EXPECT_EQ(swarm.counts().searching, 1);
}

// The swarm demo's scene on a machine too busy to keep up (as beside a browser on these two
// cores): three of ten cameras' centroids late each frame, the fusion stalled for 50 to 100 ms
// twice a second. Robots are lost and looked for again, all at once after a stall: fewer are
// tracked, but none under another's name and none posed wrong.
TEST(SwarmTracker, TheDemosSwarmOnAnOverloadedMachineKeepsItsNames) {
  SwarmScene scene =
      synthetic::load_swarm_scene((mocap::test::source_dir() / "config/swarm/scene.yaml").string());
  scene.hold_s = 0.5;
  test::SwarmRig rig = eight_cameras(9);
  const test::SwarmFigures figures =
      test::track_swarm(scene, rig, kRate_hz, 6.0, {}, {},
                        {.camera_late_fraction = 0.3, .stall_every_s = 1.0, .stall_s = 0.35});
  fmt::print("{} robot-frames, {} tracked ({:.2f} %), {} identity swaps, {} wrong poses\n",
             figures.robot_frames, figures.tracked, 100 * figures.tracked_fraction(),
             figures.identity_swaps, figures.wrong_poses);
  EXPECT_EQ(figures.identity_swaps, 0);
  EXPECT_EQ(figures.wrong_poses, 0);
  EXPECT_GE(figures.tracked_fraction(), 0.95);
}

TEST(SwarmTracker, BadOptionsAreRefusedNamingTheField) {
  SwarmTrackerOptions options;
  options.max_search_radius_m = 0.05;
  try {
    SwarmTracker swarm(SwarmDatabase{}, options);
    FAIL() << "a search radius below the start radius accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(),
                 "SwarmTrackerOptions::max_search_radius_m: 0.05 is below start_radius_m (0.1)");
  }
}

}  // namespace
}  // namespace mocap::volume
