// The constellation database: the seed's two CSV forms, the YAML form, and bad files.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include <Eigen/Geometry>

#include "test/test_support.hpp"
#include "tracking/constellation_database/constellation_database.hpp"
#include "tracking/constellation_database/cross_ratio.hpp"

namespace mocap::constellations {
namespace {

// Seed 000 Table 11, as the seed's spreadsheet exports it.
constexpr const char* kSeedSubConstellations =
    "Name,pt_A,pt_B,pt_C,pt_D\n"
    "W,0,25,175,200\n"
    "X,0,25,50,100\n"
    "Y,0,50,75,150\n"
    "Z,0,75,100,200\n";

// Seed 000 Table 12.
constexpr const char* kSeedConstellation =
    "Const_ID,4,,,\n"
    "Pts,L,M,N,O\n"
    "Name,X_coord,Y_coord,Z_coord,\n"
    "L,0,0.0993475,0,\n"
    ",0,0,0,\n"
    ",0,0.04928,0,\n"
    ",0,0.14888,0,\n"
    ",0,0.19923,0,\n"
    "M,0.30071,0.08729,0,\n"
    ",0.30071,0,0,\n"
    ",0.30071,0.04959,0,\n"
    ",0.30071,0.10034,0,\n"
    ",0.30071,0.19923,0,\n"
    "N,0.1365675,0,0,\n"
    ",0,0,0,\n"
    ",0.09431,0,0,\n"
    ",0.15125,0,0,\n"
    ",0.30071,0,0,\n"
    "O,0.1508125,0.19923,0,\n"
    ",0,0.19923,0,\n"
    ",0.05104,0.19923,0,\n"
    ",0.2515,0.19923,0,\n"
    ",0.30071,0.19923,0,\n";

TEST(CrossRatio, MatchesTheSeedDefinitionAndIgnoresDirection) {
  // R(A,C;B,D) = (AC/BC)/(AD/DB) for 0, 25, 50, 100: (50/25)/(100/75) = 1.5.
  EXPECT_DOUBLE_EQ(cross_ratio(0, 25, 50, 100), 1.5);
  EXPECT_DOUBLE_EQ(cross_ratio(-100, -50, -25, 0), 1.5);
  Eigen::Vector2d a(3, 4), d(103, 54);
  Eigen::Vector2d step = (d - a) / 100;
  EXPECT_NEAR(cross_ratio(a, a + 25 * step, a + 50 * step, d), 1.5, 1e-12);
  EXPECT_NEAR(cross_ratio(d, a + 50 * step, a + 25 * step, a), 1.5, 1e-12);
}

TEST(CrossRatio, IsInvariantUnderRandomHomographies) {
  std::srand(7);
  auto uniform = [] { return std::rand() / static_cast<double>(RAND_MAX); };
  for (int trial = 0; trial < 1000; ++trial) {
    Eigen::Matrix3d h = Eigen::Matrix3d::Identity();
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) h(i, j) += 0.4 * (uniform() - 0.5);
    }
    h(2, 0) *= 0.01;
    h(2, 1) *= 0.01;
    Eigen::Vector2d start(uniform() * 10, uniform() * 10);
    Eigen::Vector2d direction(uniform() - 0.5, uniform() - 0.5);
    std::array<double, 4> t = {0, 1 + uniform(), 3 + uniform(), 5 + uniform()};
    std::array<Eigen::Vector2d, 4> image;
    for (int i = 0; i < 4; ++i) {
      Eigen::Vector3d p = h * (start + t[i] * direction).homogeneous();
      image[i] = p.hnormalized();
    }
    ASSERT_NEAR(cross_ratio(image[0], image[1], image[2], image[3]),
                cross_ratio(t[0], t[1], t[2], t[3]), 1e-6)
        << "trial " << trial;
  }
}

TEST(ConstellationDatabase, ReadsTheSeedSubConstellationTable) {
  auto patterns = parse_sub_constellation_csv(kSeedSubConstellations, "sub.csv");
  ASSERT_EQ(patterns.size(), 4u);
  EXPECT_EQ(patterns[1].name, "X");
  EXPECT_DOUBLE_EQ(patterns[1].positions_m[3], 0.1);
  EXPECT_NEAR(patterns[1].cross_ratio, 1.5, 1e-12);
  EXPECT_NEAR(patterns[3].cross_ratio, 2.5, 1e-12);
}

TEST(ConstellationDatabase, ReadsTheSeedConstellationTableAndMergesCorners) {
  ConstellationDatabase database({}, parse_constellation_csv(kSeedConstellation, "c.csv"), "c.csv");
  ASSERT_EQ(database.constellations().size(), 1u);
  const ConstellationModel& model = database.constellations()[0];
  EXPECT_EQ(model.name, "4");
  EXPECT_EQ(model.line_names(), (std::vector<std::string>{"L", "M", "N", "O"}));
  // 16 listed points, 4 corners each listed twice.
  EXPECT_EQ(model.points.size(), 12u);
  // L and N share their first point, the origin.
  EXPECT_EQ(model.lines[0].points[0], model.lines[2].points[0]);
  EXPECT_NEAR(model.lines[0].centroid.y(), 0.0993475, 1e-12);
  EXPECT_NEAR(model.lines[0].cross_ratio, cross_ratio(0, 0.04928, 0.14888, 0.19923), 1e-12);
  EXPECT_NEAR(model.size_m, std::hypot(0.30071, 0.19923), 1e-9);
  for (size_t i = 0; i < model.points.size(); ++i) {
    Eigen::Vector3d back = model.plane_origin + model.plane_axes * model.plane_points[i];
    EXPECT_LT((back - model.points[i]).norm(), 1e-9);
  }
  // L (1.125) and O (1.042) are 8 % apart: told apart at 3 %, not at 5 % (nor at the
  // seed's 20 %).
  EXPECT_TRUE(database.ambiguities(0.03).empty());
  auto problems = database.ambiguities(0.05);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].find("'L' and 'O'"), std::string::npos) << problems[0];
}

TEST(ConstellationDatabase, NamedLinePatternsGiveTheCrossRatio) {
  std::string table = "Name,pt_A,pt_B,pt_C,pt_D\nL,0,50,150,200\n";
  ConstellationDatabase database(parse_sub_constellation_csv(table, "s.csv"),
                                 parse_constellation_csv(kSeedConstellation, "c.csv"), "c.csv");
  EXPECT_NEAR(database.constellations()[0].lines[0].cross_ratio, cross_ratio(0, 50, 150, 200),
              1e-12);
}

TEST(ConstellationDatabase, WarnsAboutLinesTooCloseToTellApart) {
  std::string yaml = R"(
constellations:
  - name: a
    lines:
      - {name: P, points: [[0, 0, 0], [0.1, 0, 0], [0.2, 0, 0], [0.4, 0, 0]]}
      - {name: Q, points: [[0, 0.1, 0], [0.1, 0.1, 0], [0.2, 0.1, 0], [0.41, 0.1, 0]]}
)";
  ConstellationDatabase database = parse_database_yaml(yaml, "db.yaml");
  auto problems = database.ambiguities(0.05);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].find("'P' and 'Q'"), std::string::npos) << problems[0];
  EXPECT_TRUE(database.ambiguities(0.001).empty());
}

void expect_error(const std::function<void()>& load, const std::string& expected) {
  try {
    load();
    ADD_FAILURE() << "no error, expected: " << expected;
  } catch (const DatabaseError& e) {
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
  }
}

TEST(ConstellationDatabase, MalformedFilesNameTheLine) {
  expect_error([] { parse_sub_constellation_csv("Name,a,b,c,d\nW,0,25,x,200\n", "s.csv"); },
               "s.csv:2: distance 'x' is not a number");
  expect_error([] { parse_sub_constellation_csv("Name,a,b,c,d\nW,0,25,175\n", "s.csv"); },
               "s.csv:2: expected Name,pt_A,pt_B,pt_C,pt_D (5 cells), got 4 cells");
  expect_error([] { parse_sub_constellation_csv("Name,a,b,c,d\nW,0,25,25,200\n", "s.csv"); },
               "s.csv:2: line 'W': the four distances must increase strictly");
  expect_error([] { parse_sub_constellation_csv("Name,a,b,c,d\n", "s.csv"); }, "has no rows");
  std::string missing_point = kSeedConstellation;
  missing_point.erase(missing_point.find(",0,0.19923,0,\n"), 14);
  expect_error([&] { parse_constellation_csv(missing_point, "c.csv"); },
               "c.csv:8: line 'L' needs 4 point rows ',x,y,z', found 3");
  std::string bad_number = kSeedConstellation;
  bad_number.replace(bad_number.find("0.09431"), 7, "0.09x31");
  expect_error([&] { parse_constellation_csv(bad_number, "c.csv"); },
               "c.csv:16: coordinate '0.09x31' is not a number");
  expect_error([] { parse_constellation_csv("Pts,L\n", "c.csv"); },
               "c.csv:1: expected 'Const_ID,<id>', got 'Pts'");
  expect_error([] { parse_constellation_csv("", "c.csv"); }, "has no constellations");
  expect_error([] { parse_database_yaml("constellations: []\n", "d.yaml"); },
               "d.yaml: the database has no constellations");
  expect_error([] { parse_database_yaml("constelations: []\n", "d.yaml"); },
               "d.yaml:1: unknown key 'constelations' in the database (did you mean "
               "'constellations'?)");
  // Inside a constellation too, and a coordinate that is not a number, by line.
  expect_error(
      [] { parse_database_yaml("constellations:\n  - name: a\n    line: []\n", "d.yaml"); },
      "d.yaml:3: unknown key 'line' in a constellation (did you mean 'lines'?)");
  expect_error(
      [] {
        parse_database_yaml(
            "constellations:\n  - name: a\n    lines:\n"
            "      - name: P\n        points: [[0, 0, 0], [0.1, 0, 0], [0.2, zero, 0], [0.4, 0, "
            "0]]\n",
            "d.yaml");
      },
      "d.yaml:5: 'a point [x, y, z]' must be a number, not 'zero'");
  expect_error(
      [] {
        parse_database_yaml(
            "constellations:\n  - name: a\n    lines:\n"
            "      - {name: P, points: [[0, 0, 0], [0.1, 0.01, 0], [0.2, 0, 0], [0.4, 0, 0]]}\n",
            "d.yaml");
      },
      "line 'P' is not straight");
  expect_error([] { load_database("/nonexistent/db.yaml"); },
               "/nonexistent/db.yaml: cannot read the constellation database");
}

TEST(ConstellationDatabase, TheShippedDatabasesLoadWithoutAmbiguities) {
  std::string config = std::string(test::source_dir()) + "/config/";
  ConstellationDatabase seed =
      load_database(config + "seed_constellation.csv", config + "seed_sub_constellations.csv");
  EXPECT_EQ(seed.line_patterns().size(), 4u);
  EXPECT_EQ(seed.constellations().size(), 1u);
  ConstellationDatabase shipped = load_database(config + "constellations.yaml");
  EXPECT_GE(shipped.constellations().size(), 8u);
  EXPECT_TRUE(shipped.ambiguities(0.03).empty()) << shipped.ambiguities(0.03).front();
}

}  // namespace
}  // namespace mocap::constellations
