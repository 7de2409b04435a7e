// The calibration's configuration and data files (calibration_config.hpp): the seed's own
// snippets (seed 002 Code 8.1-8.3, Dictionary 7.1) read as the seed meant them, the four
// transform formats of §8.2, and every error as one exact line naming file and key path.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <mocap/calibration/calibration_config.hpp>

#include "test/test_support.hpp"

namespace mocap::calibration {
namespace {

// Code 8.1 and 8.2 verbatim (the transformations and the cameras), with data entries for a
// single-camera and a stereo shot set around them: cam1 sees the board through xi12 inverted
// (seed 002 §8.4; the visgeom stereo example chains it the same way).
constexpr const char* kSeedConfig = R"({
"transformations" : [
  {
    "name" : "xiCamBoard",
    "global" : false,
    "constant" : false,
    "prior" : false
  },
  {
    "name" : "xi12",
    "global" : true,
    "constant" : false,
    "prior" : true,
    "value" : [1, 0, 0, 0, 0, 1.57]
  } ],
"cameras": [
  {
    "name" : "cam0",
    "type" : "eucm",
    "constant" : false,
    "value" : [0.01, 1, 1175, 1175, 512, 384]
  },
  {
    "name" : "cam1",
    "type" : "eucm",
    "constant" : false,
    "value" : [0.01, 1, 1175, 1175, 512, 384]
  }
],
"data" : [
  {
    "type" : "ir_data",
    "camera" : "cam0",
    "transform_chain" : [
      {"name" : "xiCamBoard", "direct" : true}
    ],
    "init" : "xiCamBoard",
    "data_file" : "merged.json",
    "object" : {
      "points" : [[0, 0.12, 0], [0, 0, 0], [0.262, 0, 0], [0.262, 0.12, 0]],
      "_points" : [[0, 0, 0], [0.262, 0, 0], [0.262, 0.12, 0], [0, 0.12, 0]]
    }
  },
  {
    "type" : "ir_data",
    "camera" : "cam1",
    "transform_chain" : [
      {"name" : "xi12", "direct" : false},
      {"name" : "xiCamBoard", "direct" : true}
    ],
    "init" : "none",
    "image_width" : 1024,
    "image_height" : 768,
    "data_file" : "merged.json",
    "object" : {
      "points" : [[0, 0.12, 0], [0, 0, 0], [0.262, 0, 0], [0.262, 0.12, 0]],
      "corners" : [0, 1, 2, 3]
    }
  }
]
}
)";

// Dictionary 7.1's layout with the seed's "Cam_id": frame 0 seen by cam0 alone, frame 1 by
// cam1 alone, frame 2 by both (the stereo shot), frame 3 by cam0 with one LED unseen, frame 4
// by a camera no entry uses.
constexpr const char* kSeedData = R"([
  [{"Cam_id": "cam0", "points": [[100, 200], [110, 200], [110, 210], [100, 210]]}],
  [{"Cam_id": "cam1", "points": [[300, 400], [310, 400], [310, 410], [300, 410]]}],
  [{"Cam_id": "cam0", "points": [[500, 100], [510, 100], [510, 110], [500, 110]]},
   {"camera": "cam1", "points": [[600, 150], [610, 150], [610, 160], [600, 160]],
    "stamp_ns": 1700000000000000000}],
  [{"Cam_id": "cam0", "points": [[1, 2], null, [5, 6], [7, 8]]}],
  [{"Cam_id": "cam3", "points": [[1, 2], [3, 4], [5, 6], [7, 8]]}]
]
)";

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "not in the text: " << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

class ConfigFiles : public ::testing::Test {
 protected:
  void SetUp() override { test::write_file(dir_ / "merged.json", kSeedData); }

  CalibrationConfig parse(const std::string& text) {
    return parse_calibration_config(text, "calib.json", dir_.path().string());
  }

  // The message of the error `text` gives, or a failure.
  std::string error_of(const std::string& text) {
    try {
      parse(text);
    } catch (const CalibrationConfigError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no error for:\n" << text;
    return {};
  }

  std::string data_path() const { return (dir_ / "merged.json").string(); }

  test::TempDir dir_;
};

TEST_F(ConfigFiles, ReadsTheSeedsSnippets) {
  const CalibrationConfig config = parse(kSeedConfig);
  EXPECT_EQ(config.source, "calib.json");
  ASSERT_EQ(config.transformations.size(), 2u);
  const TransformSpec& board = config.transformations[0];
  EXPECT_EQ(board.name, "xiCamBoard");
  EXPECT_FALSE(board.global);
  EXPECT_FALSE(board.constant);
  EXPECT_FALSE(board.prior);
  EXPECT_FALSE(board.value);
  const TransformSpec& xi12 = config.transformations[1];
  EXPECT_EQ(xi12.name, "xi12");
  EXPECT_TRUE(xi12.global);
  EXPECT_TRUE(xi12.prior);
  EXPECT_EQ(xi12.prior_stiffness, 1.0);
  ASSERT_TRUE(xi12.value);
  EXPECT_TRUE(xi12.value->translation().isApprox(Eigen::Vector3d(1, 0, 0)));
  const Eigen::Matrix3d about_z =
      Eigen::AngleAxisd(1.57, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_TRUE(xi12.value->linear().isApprox(about_z, 1e-12));

  ASSERT_EQ(config.cameras.size(), 2u);
  EXPECT_EQ(config.cameras[1].name, "cam1");
  EXPECT_EQ(config.cameras[1].type, "eucm");
  EXPECT_FALSE(config.cameras[1].constant);
  EXPECT_EQ(config.cameras[1].value, (std::vector<double>{0.01, 1, 1175, 1175, 512, 384}));

  ASSERT_EQ(config.data.size(), 2u);
  const DataSpec& mono = config.data[0];
  EXPECT_EQ(mono.type, "ir_data");
  EXPECT_EQ(mono.camera, "cam0");
  ASSERT_EQ(mono.transform_chain.size(), 1u);
  EXPECT_EQ(mono.transform_chain[0].name, "xiCamBoard");
  EXPECT_TRUE(mono.transform_chain[0].direct);
  EXPECT_FALSE(mono.init);
  // Defaults: the PixArt sensor, every object point a corner in order.
  EXPECT_EQ(mono.image_width, 1024);
  EXPECT_EQ(mono.image_height, 768);
  EXPECT_EQ(mono.data_file, "merged.json");
  EXPECT_EQ(mono.data_path, data_path());
  ASSERT_EQ(mono.object_points.size(), 4u);
  EXPECT_EQ(mono.object_points[0], Eigen::Vector3d(0, 0.12, 0));
  EXPECT_EQ(mono.object_points[2], Eigen::Vector3d(0.262, 0, 0));
  EXPECT_EQ(mono.corners, (std::vector<int>{0, 1, 2, 3}));
  // Frames 0 and 2 hold cam0 with all corners; frame 3 lacks one, frames 1 and 4 lack cam0.
  ASSERT_EQ(mono.shots.size(), 2u);
  EXPECT_EQ(mono.shots[0].frame, 0u);
  EXPECT_EQ(mono.shots[1].frame, 2u);
  ASSERT_EQ(mono.shots[1].points.size(), 4u);
  EXPECT_EQ(mono.shots[1].points[0], Eigen::Vector2d(500, 100));
  EXPECT_EQ(mono.shots[1].points[3], Eigen::Vector2d(500, 110));

  const DataSpec& stereo = config.data[1];
  ASSERT_EQ(stereo.transform_chain.size(), 2u);
  EXPECT_EQ(stereo.transform_chain[0].name, "xi12");
  EXPECT_FALSE(stereo.transform_chain[0].direct);
  ASSERT_EQ(stereo.shots.size(), 2u);
  EXPECT_EQ(stereo.shots[0].frame, 1u);
  EXPECT_EQ(stereo.shots[1].frame, 2u);
  EXPECT_EQ(stereo.shots[1].points[1], Eigen::Vector2d(610, 150));
}

TEST_F(ConfigFiles, CornersPickAndOrderTheObjectPoints) {
  const CalibrationConfig config =
      parse(replaced(kSeedConfig, R"("corners" : [0, 1, 2, 3])", R"("corners" : [3, 0, 1, 2])"));
  EXPECT_EQ(config.data[1].corners, (std::vector<int>{3, 0, 1, 2}));
}

TEST_F(ConfigFiles, InitTakesATransformValueAndStiffnessWeighsThePrior) {
  std::string text = replaced(kSeedConfig, R"("init" : "none")", R"("init" : [0, 0, 2, 0, 0, 0])");
  text = replaced(text, R"("prior" : true,)", R"("prior" : true, "stiffness" : 25,)");
  const CalibrationConfig config = parse(text);
  ASSERT_TRUE(config.data[1].init);
  Eigen::Isometry3d expected = Eigen::Isometry3d::Identity();
  expected.translation() = Eigen::Vector3d(0, 0, 2);
  EXPECT_TRUE(config.data[1].init->isApprox(expected));
  EXPECT_EQ(config.transformations[1].prior_stiffness, 25);
}

TEST_F(ConfigFiles, LoadResolvesDataFilesBesideTheConfig) {
  test::write_file(dir_ / "calib.json", kSeedConfig);
  const std::string path = (dir_ / "calib.json").string();
  const CalibrationConfig config = load_calibration_config(path);
  EXPECT_EQ(config.source, path);
  EXPECT_EQ(config.data[0].data_path, data_path());
  EXPECT_EQ(config.data[0].shots.size(), 2u);
  try {
    load_calibration_config((dir_ / "missing.json").string());
    ADD_FAILURE() << "no error";
  } catch (const CalibrationConfigError& e) {
    EXPECT_EQ(std::string(e.what()), (dir_ / "missing.json").string() +
                                         ": cannot read the calibration configuration: No such "
                                         "file or directory");
  }
}

// --- the transform formats (seed 002 §8.2) ----------------------------------------------------

TEST(TransformValues, EveryFormatGivesTheTransformBuiltByHand) {
  // 3 numbers: a posture in the plane.
  Eigen::Isometry3d planar = Eigen::Isometry3d::Identity();
  planar.translate(Eigen::Vector3d(0.3, -0.2, 0));
  planar.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()));
  const std::vector<double> three = {0.3, -0.2, 0.7};
  EXPECT_TRUE(transform_from_values(three).isApprox(planar, 1e-12));

  // 6, 7 and 12 numbers: one 3D transform, written three ways.
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, 3).normalized();
  const double angle = 0.9;
  const Eigen::Vector3d t(0.1, -0.2, 0.3);
  Eigen::Isometry3d hand = Eigen::Isometry3d::Identity();
  hand.translate(t);
  hand.rotate(Eigen::AngleAxisd(angle, axis));
  const Eigen::Vector3d r = angle * axis;
  const std::vector<double> six = {t.x(), t.y(), t.z(), r.x(), r.y(), r.z()};
  EXPECT_TRUE(transform_from_values(six).isApprox(hand, 1e-12));

  const Eigen::Quaterniond q(Eigen::AngleAxisd(angle, axis));
  const std::vector<double> seven = {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()};
  EXPECT_TRUE(transform_from_values(seven).isApprox(hand, 1e-12));

  const Eigen::Matrix3d m = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
  const std::vector<double> twelve = {m(0, 0), m(0, 1), m(0, 2), t.x(),   m(1, 0), m(1, 1),
                                      m(1, 2), t.y(),   m(2, 0), m(2, 1), m(2, 2), t.z()};
  EXPECT_TRUE(transform_from_values(twelve).isApprox(hand, 1e-12));

  // And back to six numbers.
  const std::vector<double> back = transform_to_values6(hand);
  ASSERT_EQ(back.size(), 6u);
  for (size_t i = 0; i < 6; ++i) EXPECT_NEAR(back[i], six[i], 1e-12) << i;
  EXPECT_EQ(transform_to_values6(Eigen::Isometry3d::Identity()), std::vector<double>(6, 0.0));
}

TEST(TransformValues, RefusesWhatIsNotATransform) {
  auto message = [](std::vector<double> values) {
    try {
      transform_from_values(values);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message({1, 2, 3, 4, 5}), "3, 6, 7 or 12 numbers, not 5");
  EXPECT_EQ(message({}), "3, 6, 7 or 12 numbers, not 0");
  EXPECT_EQ(message({0, 0, NAN}), "number 2 is nan");
  EXPECT_EQ(message({0, 0, 0, 0, 0, 0, 2}), "the quaternion [qx, qy, qz, qw] has norm 2, not 1");
  EXPECT_EQ(message({2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}),
            "the 3x3 part is not a rotation (|R'R - I| = 3, det R = 2)");
  // A mirror is orthonormal but no rotation.
  EXPECT_NE(message({-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}).find("not a rotation"),
            std::string::npos);
}

TEST_F(ConfigFiles, EveryValueFormatInTheConfigGivesTheSameTransform) {
  const Eigen::Isometry3d expected =
      transform_from_values(std::vector<double>{1, 0, 0, 0, 0, 1.57});
  const Eigen::Quaterniond q(expected.rotation());
  const Eigen::Matrix3d m = expected.rotation();
  const std::vector<std::string> values = {
      "[1, 0, 1.57]",
      "[1, 0, 0, " + std::to_string(q.x()) + ", " + std::to_string(q.y()) + ", " +
          std::to_string(q.z()) + ", " + std::to_string(q.w()) + "]",
      "[" + std::to_string(m(0, 0)) + ", " + std::to_string(m(0, 1)) + ", 0, 1, " +
          std::to_string(m(1, 0)) + ", " + std::to_string(m(1, 1)) + ", 0, 0, 0, 0, 1, 0]"};
  for (const std::string& value : values) {
    const CalibrationConfig config = parse(replaced(kSeedConfig, "[1, 0, 0, 0, 0, 1.57]", value));
    // std::to_string keeps 6 decimals.
    EXPECT_TRUE(config.transformations[1].value->isApprox(expected, 1e-5)) << value;
  }
}

// --- errors ----------------------------------------------------------------------------------

TEST_F(ConfigFiles, ErrorsNameTheFileAndTheKeyPath) {
  struct Case {
    std::string from, to, expected;
  };
  const std::vector<Case> cases = {
      {R"("transform_chain" : [
      {"name" : "xi12", "direct" : false},)",
       R"("transform_chain" : [
      {"name" : "xi99", "direct" : false},)",
       "calib.json:48: data[1].transform_chain[0].name: 'xi99' is not a declared transformation"},
      {R"({"name" : "xi12", "direct" : false})", R"({"name" : "xi1", "direct" : false})",
       "calib.json:48: data[1].transform_chain[0].name: 'xi1' is not a declared transformation "
       "(did you mean 'xi12'?)"},
      {"[1, 0, 0, 0, 0, 1.57]", "[1, 0, 0, 0, 0]",
       "calib.json:14: transformations[1].value: 3, 6, 7 or 12 numbers, not 5"},
      {"[1, 0, 0, 0, 0, 1.57]", "[1, 0, \"x\"]",
       "calib.json:14: transformations[1].value[2]: a number, not the string \"x\""},
      {R"("type" : "eucm",)", R"("type" : "fisheye",)",
       "calib.json:19: cameras[0].type: unknown camera type 'fisheye' (eucm, mei, pinhole, ucm)"},
      {R"("value" : [0.01, 1, 1175, 1175, 512, 384])", R"("value" : [0.01, 1, 1175, 1175, 512])",
       "calib.json:21: cameras[0].value: eucm takes 6 numbers (alpha, beta, fu, fv, u0, v0), not "
       "5"},
      {R"("type" : "eucm",
    "constant" : false,
    "value" : [0.01, 1, 1175, 1175, 512, 384])",
       R"("type" : "pinhole",
    "value" : [1175, 1175, 512, 384, 0])",
       "calib.json:20: cameras[0].value: pinhole takes 4 or 9 numbers (fx, fy, cx, cy, then k1, "
       "k2, "
       "p1, p2, k3), not 5"},
      {R"("constant" : false,
    "value" : [0.01)",
       R"("constnat" : false,
    "value" : [0.01)",
       "calib.json:20: unknown key 'constnat' in cameras[0] (did you mean 'constant'?)"},
      {R"("data" : [)", R"("data" : [], "solver" : [)",
       "calib.json:30: unknown key 'solver' in the top level (keys: transformations, cameras, "
       "data)"},
      {R"("name" : "xi12",)", R"("name" : "xiCamBoard",)",
       "calib.json:10: transformations[1].name: 'xiCamBoard' is declared twice"},
      {R"("name" : "cam1",)", R"("name" : "cam0",)",
       "calib.json:24: cameras[1].name: 'cam0' is declared twice"},
      {R"("camera" : "cam1",)", R"("camera" : "camera9",)",
       "calib.json:46: data[1].camera: 'camera9' is not a declared camera"},
      {R"("camera" : "cam1",)", R"("camera" : "cam2",)",
       "calib.json:46: data[1].camera: 'cam2' is not a declared camera (did you mean 'cam0'?)"},
      {R"("global" : true,)", R"("global" : false,)",
       "calib.json:47: data[1].transform_chain: needs exactly one per-shot transformation (the "
       "board's pose), has 2: xi12, xiCamBoard"},
      {R"("global" : false,)", R"("global" : true,)",
       "calib.json:34: data[0].transform_chain: needs exactly one per-shot transformation (the "
       "board's pose), has 0"},
      {R"("image_width" : 1024,)", R"("image_width" : 0,)",
       "calib.json:52: data[1].image_width: must be positive, not 0"},
      {R"("image_height" : 768,)", R"("image_height" : -768,)",
       "calib.json:53: data[1].image_height: must be positive, not -768"},
      {R"("image_height" : 768,)", R"("image_height" : 76.8,)",
       "calib.json:53: data[1].image_height: a whole number, not 76.8"},
      {R"("type" : "ir_data",)", R"("type" : "video",)",
       "calib.json:32: data[0].type: unknown data type 'video' (ir_data, images)"},
      {R"("init" : "none",)", R"("init" : "xi12",)",
       "calib.json:51: data[1].init: a transform value, \"none\" or 'xiCamBoard' (the chain's "
       "per-shot transformation), not 'xi12'"},
      {R"("corners" : [0, 1, 2, 3])", R"("corners" : [0, 1, 2, 4])",
       "calib.json:57: data[1].object.corners[3]: 4 is not a point: there are 4"},
      {R"("corners" : [0, 1, 2, 3])", R"("corners" : [0, 1, 1, 3])",
       "calib.json:57: data[1].object.corners[2]: 1 appears twice"},
      {R"("global" : true,)", R"("global" : "yes",)",
       "calib.json:11: transformations[1].global: true or false, not the string \"yes\""},
      {R"("prior" : true,)", R"("prior" : false, "stiffness" : 3,)",
       "calib.json:13: transformations[1].stiffness: only with \"prior\": true"},
      {R"("prior" : true,)", R"("prior" : true, "stiffness" : 0,)",
       "calib.json:13: transformations[1].stiffness: must be positive, not 0"},
      {R"("constant" : false,
    "prior" : true,)",
       R"("constant" : true,
    "prior" : true,)",
       "calib.json:9: transformations[1]: 'constant' and 'prior' exclude each other: a constant "
       "is exact"},
      {R"("prior" : true,
    "value" : [1, 0, 0, 0, 0, 1.57])",
       R"("prior" : true)", "calib.json:9: transformations[1]: needs 'value' for \"prior\": true"},
      {R"("name" : "xi12",)", R"("name" : "xi12", "name" : "xi13",)",
       "calib.json:10: 'name' appears twice in transformations[1]"},
      {R"("camera" : "cam1",
    "transform_chain")",
       R"("transform_chain")", "calib.json:44: data[1]: needs 'camera'"},
      {R"("data_file" : "merged.json",
    "object" : {
      "points" : [[0, 0.12, 0], [0, 0, 0], [0.262, 0, 0], [0.262, 0.12, 0]],
      "corners")",
       R"("data_file" : "absent.json",
    "object" : {
      "points" : [[0, 0.12, 0], [0, 0, 0], [0.262, 0, 0], [0.262, 0.12, 0]],
      "corners")",
       "calib.json:54: data[1].data_file: cannot read '" + (dir_ / "absent.json").string() +
           "': No such file or directory"},
  };
  for (const Case& c : cases) {
    EXPECT_EQ(error_of(replaced(kSeedConfig, c.from, c.to)), c.expected) << "case: " << c.to;
  }
}

TEST_F(ConfigFiles, MalformedJsonGivesItsPosition) {
  EXPECT_EQ(error_of("{\n \"a\": [1, 2\n }"), "calib.json:3:2: JSON error: illegal flow end");
  EXPECT_EQ(error_of("[]"),
            "calib.json:1: the configuration is an object with 'transformations', 'cameras' and "
            "'data', not a list of 0");
}

// --- data files ------------------------------------------------------------------------------

TEST_F(ConfigFiles, DataFileErrorsNameThatFileAndItsKeyPath) {
  struct Case {
    std::string data, expected;
  };
  const std::string file = data_path();
  const std::vector<Case> cases = {
      {R"([[], [], [], [{"camera": "cam0", "points": [[1, 2], [3, 4], [5, 6]]}]])",
       file + ":1: [3][0].points: 3 points, but calib.json data[0] has 4 corners"},
      {R"([[{"camera": "cam0", "points": [[1, 2], [3, 4], [5], [7, 8]]}]])",
       file + ":1: [0][0].points[2]: [u, v] in pixels or null, not a list of 1"},
      {R"([[{"camera": "cam0", "points": [[1, 2], [3, 4], [5, "6"], [7, 8]]}]])",
       file + ":1: [0][0].points[2][1]: a number, not the string \"6\""},
      {R"([[{"points": [[1, 2], [3, 4], [5, 6], [7, 8]]}]])", file + ":1: [0][0]: needs 'camera'"},
      {R"([[{"camera": "cam0", "pionts": []}]])",
       file + ":1: unknown key 'pionts' in [0][0] (did you mean 'points'?)"},
      {R"([[{"camera": "cam0", "points": []}, {"Cam_id": "cam0", "points": []}]])",
       file + ":1: [0][1].Cam_id: 'cam0' appears twice in the frame"},
      {R"({"frames": []})", file + ":1: a data file is a list of frames, not an object"},
      {R"([{"camera": "cam0"}])",
       file + ":1: [0]: a frame is a list of {\"camera\": name, \"points\": [...]}, not an object"},
      {"[[{\"camera\": \"cam0\",\n \"points\": [[1, 2] [3, 4]]}]]",
       file + ":2:20: JSON error: end of sequence flow not found"},
      // Missing cameras: the entry would calibrate nothing.
      {R"([[{"camera": "cam1", "points": [[1, 2], [3, 4], [5, 6], [7, 8]]}]])",
       "calib.json:31: data[0]: " + file + " has no frame of camera 'cam0' (it has cam1)"},
      {"[]",
       "calib.json:31: data[0]: " + file + " has no frame of camera 'cam0' (it has no cameras)"},
      // Missing points: no complete frame.
      {R"([[{"camera": "cam0", "points": [[1, 2], null, [5, 6], [7, 8]]}],
           [{"camera": "cam0", "points": [null, null, null, null]}]])",
       "calib.json:31: data[0]: none of the 2 frames of 'cam0' in " + file + " has all 4 corners"},
  };
  for (const Case& c : cases) {
    test::write_file(dir_ / "merged.json", c.data);
    EXPECT_EQ(error_of(kSeedConfig), c.expected) << "data: " << c.data;
  }
}

TEST_F(ConfigFiles, FramesWithoutTheCameraOrWithUnseenPointsAreNotShots) {
  test::write_file(dir_ / "merged.json", R"([
  [{"camera": "cam1", "points": [[1, 1], [2, 2], [3, 3], [4, 4]]}],
  [{"camera": "cam0", "points": [[1, 2], [3, 4], [5, 6], [7, 8]]},
   {"camera": "cam1", "points": [null, [2, 2], [3, 3], [4, 4]]}],
  [],
  [{"camera": "cam0", "points": [[9, 9], [8, 8], [7, 7], [6, 6]]},
   {"camera": "cam1", "points": [[5, 5], [6, 6], [7, 7], [8, 8]]}]
])");
  const CalibrationConfig config = parse(kSeedConfig);
  ASSERT_EQ(config.data[0].shots.size(), 2u);
  EXPECT_EQ(config.data[0].shots[0].frame, 1u);
  EXPECT_EQ(config.data[0].shots[1].frame, 3u);
  EXPECT_EQ(config.data[0].shots[1].points[0], Eigen::Vector2d(9, 9));
  ASSERT_EQ(config.data[1].shots.size(), 2u);
  EXPECT_EQ(config.data[1].shots[0].frame, 0u);
  EXPECT_EQ(config.data[1].shots[1].frame, 3u);
  EXPECT_EQ(config.data[1].shots[1].points[3], Eigen::Vector2d(8, 8));
}

// visgeom's stereo example (data/calib_stereo_example.json) as visgeom has it, with its image
// folders made relative and four names per camera.
constexpr const char* kVisgeomStereo = R"({
"transformations" : [
    {"name" : "xiCamBoard1", "global" : false, "constant" : false, "prior" : false},
    {"name" : "xiCamBoardStereo", "global" : false, "constant" : false, "prior" : false},
    {
        "name" : "xiCam12",
        "global" : true,
        "constant" : false,
        "prior" : true,
        "value" : [0, -0.3, 0, 0, 0, 0]
    }
],
"cameras": [
    {"name" : "camera1", "type" : "eucm", "constant" : false, "value" : [0.55, 1.2, 200, 200,  320,  240]},
    {"name" : "camera2", "type" : "eucm", "constant" : false, "value" : [0.55, 1.2, 200, 200,  320,  240]}
],
"data" : [ 
    {
        "type" : "images",
        "camera" : "camera1",
        "transform_chain" : [
            {"name" : "xiCamBoardStereo", "direct" : true}
        ],
        "init" : "xiCamBoardStereo",
        "object" : {"type" : "checkboard", "rows" : 5, "cols" : 8, "size" : 0.1},
        "parameters" : ["_check_extraction", "show_outliers", "_user_guided", "improve_detection"],
        "images" : {
            "prefix" : "stereo/bottom/",
            "names" : ["000001.png", "000002.png", "000003.png", "000004.png"]
        }
    }, 
    {
        "type" : "images",
        "camera" : "camera2",
        "transform_chain" : [
            {"name" : "xiCam12", "direct" : false},
            {"name" : "xiCamBoardStereo", "direct" : true}
        ],
        "init" : "none",
        "object" : {"type" : "checkboard", "rows" : 5, "cols" : 8, "size" : 0.1},
        "parameters" : ["check_extraction", "_show_outliers", "user_guided", "_save_outlire_images"],
        "images" : {
            "prefix" : "stereo/top/",
            "names" : ["000001.png", "000002.png", "000003.png", "000004.png"]
        }
    },
    {
        "type" : "images",
        "camera" : "camera1",
        "transform_chain" : [
            {"name" : "xiCamBoard1", "direct" : true}
        ],
        "init" : "xiCamBoard1",
        "object" : {"type" : "checkboard", "rows" : 5, "cols" : 8, "size" : 0.1},
        "parameters" : ["check_extraction", "draw_improved"],
        "draw_scale" : 2,
        "images" : {
            "prefix" : "/data/mono/",
            "names" : ["a.png"]
        }
    }
]
}
)";

TEST_F(ConfigFiles, ReadsVisgeomsStereoExample) {
  const CalibrationConfig config = parse(kVisgeomStereo);
  ASSERT_EQ(config.data.size(), 3u);
  const DataSpec& bottom = config.data[0];
  EXPECT_EQ(bottom.type, "images");
  EXPECT_EQ(bottom.board_rows, 5);
  EXPECT_EQ(bottom.board_columns, 8);
  ASSERT_EQ(bottom.object_points.size(), 40u);
  ASSERT_EQ(bottom.corners.size(), 40u);
  // Row by row: corner 9 is the second row's second corner.
  EXPECT_EQ(bottom.object_points[9], Eigen::Vector3d(0.1, 0.1, 0));
  EXPECT_EQ(bottom.object_points[39], Eigen::Vector3d(7 * 0.1, 4 * 0.1, 0));
  ASSERT_EQ(bottom.image_files.size(), 4u);
  EXPECT_EQ(bottom.image_files[1], (dir_ / "stereo/bottom/000002.png").string());
  EXPECT_EQ(config.data[2].image_files[0], "/data/mono/a.png");
  EXPECT_TRUE(bottom.shots.empty()) << "the boards are found by whoever reads the images";
  EXPECT_EQ(bottom.image_width, 0);
  // The stereo pair shares its board poses per image index.
  EXPECT_EQ(bottom.data_path, config.data[1].data_path);
  // Flags: the ones that mean something here are on where they are on; the others are listed
  // once; '_' switches a flag off.
  EXPECT_EQ(bottom.flags, (std::vector<std::string>{"show_outliers", "improve_detection"}));
  EXPECT_TRUE(config.data[1].flags.empty());
  EXPECT_EQ(config.ignored_flags,
            (std::vector<std::string>{"check_extraction", "user_guided", "draw_improved"}));
}

TEST_F(ConfigFiles, VisgeomFormErrorsNameTheKeyPath) {
  struct Case {
    std::string from, to, expected;
  };
  const std::vector<Case> cases = {
      {R"("show_outliers", "_user_guided")", R"("show_outlier", "_user_guided")",
       "calib.json:26: data[0].parameters[1]: unknown visgeom flag 'show_outlier' (did you mean "
       "'show_outliers'?)"},
      {R"("_check_extraction", "show_outliers")", R"("_check_extractoin", "show_outliers")",
       "calib.json:26: data[0].parameters[0]: unknown visgeom flag 'check_extractoin' (did you "
       "mean "
       "'check_extraction'?)"},
      {R"("type" : "checkboard", "rows" : 5, "cols" : 8, "size" : 0.1},
        "parameters" : ["_check)",
       R"("type" : "circles", "rows" : 5, "cols" : 8, "size" : 0.1},
        "parameters" : ["_check)",
       "calib.json:25: data[0].object.type: 'checkboard' (visgeom's name) or 'chessboard', not "
       "'circles'"},
      {R"("rows" : 5, "cols" : 8, "size" : 0.1},
        "parameters" : ["_check)",
       R"("rows" : 1, "cols" : 8, "size" : 0.1},
        "parameters" : ["_check)",
       "calib.json:25: data[0].object.rows: at least 2 inner corners, not 1"},
      {R"("images" : {
            "prefix" : "stereo/bottom/",)",
       R"("imagess" : {
            "prefix" : "stereo/bottom/",)",
       "calib.json:27: unknown key 'imagess' in data[0] (did you mean 'images'?)"},
      {R"("prefix" : "/data/mono/",
            "names" : ["a.png"])",
       R"("prefix" : "/data/mono/",
            "names" : [])",
       "calib.json:59: data[2].images.names: is empty"},
      {R"("draw_scale" : 2,)", R"("draw_scale" : "big",)",
       "calib.json:56: data[2].draw_scale: a number, not the string \"big\""},
  };
  for (const Case& c : cases) {
    EXPECT_EQ(error_of(replaced(kVisgeomStereo, c.from, c.to)), c.expected) << c.to;
  }
}

}  // namespace
}  // namespace mocap::calibration
