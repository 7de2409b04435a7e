// Rigid bodies of any shape (rigid_body_database.hpp, rigid_body_identification.hpp): the best
// fit, bodies found among noisy markers with distractors and a missing marker, a mirror image
// refused, and the database's errors, bodies that cannot be told apart among them.
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "test/volume/synthetic_volume.hpp"
#include "tracking/pose_estimator/planar_pose.hpp"
#include "volume/rigid_bodies/rigid_body_identification.hpp"

namespace mocap::volume {
namespace {

constexpr double kTolerance = 0.004;

Eigen::Isometry3d random_transform(std::mt19937& random) {
  std::uniform_real_distribution<double> unit(-1, 1);
  const Eigen::Vector4d q = test::draws<4>(unit, random);
  const Eigen::Vector3d t = test::draws<3>(unit, random);
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  transform.linear() = Eigen::Quaterniond(q.normalized()).toRotationMatrix();
  transform.translation() = Eigen::Vector3d(2 * t.x(), 2 * t.y(), 1 + t.z());
  return transform;
}

const char* kBodies = R"(bodies:
  - name: wand
    markers: [[0, 0, 0], [0.10, -0.04, 0], [0.22, 0.12, 0]]
  - name: drone
    markers: [[-0.07, 0.11, 0.03], [0.08, -0.02, 0.04], [0.11, -0.11, 0.03], [0.02, 0.11, 0.04]]
  - name: helmet
    markers: [[0, 0, 0.1], [0.04, 0.09, 0.04], [-0.06, 0.01, 0.12], [0.05, -0.11, 0.19],
              [0.11, 0.11, 0.04]]
)";

TEST(RigidBodies, BestFitRecoversATransform) {
  std::mt19937 random(1);
  const Eigen::Isometry3d truth = random_transform(random);
  const std::vector<Eigen::Vector3d> from = {{0, 0, 0}, {1, 0, 0}, {0, 2, 0}, {0.3, 0.2, 1}};
  std::vector<Eigen::Vector3d> to;
  for (const auto& p : from) to.push_back(truth * p);
  EXPECT_TRUE(best_fit_transform(from, to).isApprox(truth, 1e-9));
  EXPECT_THROW(best_fit_transform({from[0], from[1]}, {to[0], to[1]}), std::invalid_argument);
}

// Three bodies among ten distractors, 0.5 mm of noise, one of the drone's markers hidden: each
// found with its own markers and its pose within a millimetre and a degree.
TEST(RigidBodies, FoundAmongDistractorsWithAMarkerMissing) {
  const RigidBodyDatabase database = parse_rigid_bodies(kBodies, "bodies.yaml", kTolerance, 3);
  std::mt19937 random(5);
  std::normal_distribution<double> noise(0, 0.0005 / std::sqrt(3.0));
  std::uniform_real_distribution<double> anywhere(-2, 2);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Eigen::Vector3d> markers;
    std::vector<Eigen::Isometry3d> truths;
    std::vector<std::vector<int>> indices(database.bodies.size());
    for (size_t b = 0; b < database.bodies.size(); ++b) {
      truths.push_back(random_transform(random));
      for (size_t k = 0; k < database.bodies[b].markers.size(); ++k) {
        if (database.bodies[b].name == "drone" && k == 2) {
          indices[b].push_back(-1);
          continue;
        }
        indices[b].push_back(static_cast<int>(markers.size()));
        markers.push_back(truths[b] * database.bodies[b].markers[k] +
                          test::draws<3>(noise, random));
      }
    }
    for (int d = 0; d < 10; ++d) {
      const Eigen::Vector3d at = test::draws<3>(anywhere, random);
      markers.emplace_back(at.x(), at.y(), 1 + at.z() / 2);
    }
    const std::vector<IdentifiedBody> found = identify_rigid_bodies(database, markers);
    ASSERT_EQ(found.size(), database.bodies.size()) << "trial " << trial;
    for (size_t b = 0; b < found.size(); ++b) {
      EXPECT_EQ(found[b].name, database.bodies[b].name);
      EXPECT_EQ(found[b].measured, indices[b]) << found[b].name << ", trial " << trial;
      EXPECT_LT((found[b].world_from_body.translation() - truths[b].translation()).norm(), 1e-3);
      EXPECT_LT(
          pose::rotation_angle_between(Eigen::Quaterniond(found[b].world_from_body.rotation()),
                                       Eigen::Quaterniond(truths[b].rotation())),
          M_PI / 180)
          << found[b].name << ", trial " << trial;
    }
  }
}

// A mirror image has every distance of the body, but no rotation maps one onto the other.
TEST(RigidBodies, AMirrorImageIsNotTheBody) {
  const RigidBodyDatabase database = parse_rigid_bodies(kBodies, "bodies.yaml", kTolerance, 3);
  const RigidBody& helmet = database.bodies[2];
  std::vector<Eigen::Vector3d> mirrored;
  for (const auto& p : helmet.markers) mirrored.emplace_back(-p.x(), p.y(), p.z());
  RigidBodyIdentificationOptions all_markers;
  all_markers.min_markers = 5;
  EXPECT_TRUE(identify_rigid_bodies({{helmet}}, mirrored, all_markers).empty());
  EXPECT_EQ(identify_rigid_bodies({{helmet}}, helmet.markers, all_markers).size(), 1u);
}

TEST(RigidBodies, DatabaseErrorsNameTheLine) {
  struct Case {
    std::string text, expected;
  };
  const std::vector<Case> cases = {
      {"bodies:\n  - name: a\n    markers: [[0, 0, 0], [1, 0, 0]]\n",
       "b.yaml:3: body 'a' needs 3 or more markers, not a list of 2"},
      {"bodies:\n  - name: a\n    markers: [[0, 0, 0], [1, 0, 0], [1, 0.005, 0]]\n",
       "b.yaml:3: body 'a': marker 2 is within 0.01 m of marker 1"},
      {"bodies:\n  - name: a\n    markers: [[0, 0, 0], [1, 0, 0], [0, 2, 0]]\n"
       "  - name: a\n    markers: [[0, 0, 0], [1, 0, 0], [0, 3, 0]]\n",
       "b.yaml:4: body 'a' is declared twice"},
      {"bodies:\n  - name: a\n    marker: []\n",
       "b.yaml:3: unknown key 'marker' in a body (did you mean 'markers'?)"},
      // The same triangle, moved: no distance tells them apart.
      {"bodies:\n  - name: a\n    markers: [[0, 0, 0], [0.1, 0, 0], [0, 0.2, 0]]\n"
       "  - name: b\n    markers: [[1, 1, 0], [1.1, 1, 0], [1, 1.2, 0]]\n",
       "b.yaml:4: body 'b' cannot be told apart from 'a' (line 2): 3 or more markers of one "
       "match the other's distances within 0.008 m; move a marker"},
      // Two of its triangles alike: seen by three markers, which way round would be a guess.
      {"bodies:\n  - name: a\n    markers: [[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0]]\n",
       "b.yaml:2: body 'a': its markers 0, 1, 2 could be taken for its markers 0, 2, 1 "
       "(distances within 0.008 m), so its pose is ambiguous when only 3 are seen; move a "
       "marker, or identify bodies from more markers (min_markers)"},
      // Three of a four-marker body's, within the tolerance: seeing those three would be both.
      {"bodies:\n  - name: a\n    markers: [[0, 0, 0], [0.1, 0, 0], [0, 0.2, 0], [0.3, 0.3, 0.1]]\n"
       "  - name: b\n    markers: [[0, 0, 0], [0.103, 0, 0], [0, 0.2, 0]]\n",
       "b.yaml:4: body 'b' cannot be told apart from 'a' (line 2): 3 or more markers of one "
       "match the other's distances within 0.008 m; move a marker"},
  };
  for (const Case& c : cases) {
    try {
      parse_rigid_bodies(c.text, "b.yaml", kTolerance, 3);
      ADD_FAILURE() << "no error for:\n" << c.text;
    } catch (const RigidBodyError& e) {
      EXPECT_EQ(std::string(e.what()), c.expected);
    }
  }
  // Told apart once a marker moves by more than twice the tolerance.
  EXPECT_EQ(parse_rigid_bodies("bodies:\n  - name: a\n    markers: [[0, 0, 0], [0.1, 0, 0], [0, "
                               "0.2, 0]]\n  - name: b\n    markers: [[0, 0, 0], [0.12, 0, 0], "
                               "[0, 0.2, 0]]\n",
                               "b.yaml", kTolerance, 3)
                .bodies.size(),
            2u);
}

}  // namespace
}  // namespace mocap::volume
