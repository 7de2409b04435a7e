// Camera models: the EUCM lens against values worked out by hand and against its own inverse,
// the unified (UCM, Mei) lenses against the EUCM and OpenCV's omnidirectional camera,
// the lens formulas with Ceres Jets against finite differences, the factory, and camera files
// (EUCM and poses) through the writer and back.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include <ceres/jet.h>
#include <Eigen/Geometry>

#include <mocap/calibration/camera_factory.hpp>
#include <mocap/calibration/camera_file.hpp>
#include <mocap/calibration/eucm_camera.hpp>
#include <mocap/calibration/lens_models.hpp>
#include <mocap/calibration/pinhole_camera.hpp>
#include <mocap/calibration/unified_camera.hpp>
#include <opencv2/ccalib/omnidir.hpp>

#include "test/test_support.hpp"

namespace mocap::calibration {
namespace {

constexpr double kDeg = std::numbers::pi / 180;

// A PixArt-like sensor behind lenses from nearly pinhole to fisheye.
const EucmCamera kMildLens(1024, 768, {0.3, 1.1, 1300, 1310, 511.5, 383.5});
const EucmCamera kWideLens(1024, 768, {0.62, 1.05, 420, 425, 515, 380});
const EucmCamera kFisheye(1024, 768, {0.9, 0.85, 560, 560, 511.5, 383.5});

std::string error_of(const std::function<void()>& action) {
  try {
    action();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// ---------------------------------------------------------------------------------------------
// EUCM.

TEST(EucmCamera, ProjectsAndUnprojectsAPointWorkedOutByHand) {
  // alpha 0.8, beta 0.36; point (3, 4, 4): rho = sqrt(16 + 0.36·25) = 5,
  // d = 0.8·5 + 0.2·4 = 4.8, u = 480·3/4.8 + 320 = 620, v = 600·4/4.8 + 240 = 740.
  EucmCamera camera(1280, 960, {0.8, 0.36, 480, 600, 320, 240});
  auto pixel = camera.project({3, 4, 4});
  ASSERT_TRUE(pixel);
  EXPECT_NEAR(pixel->x(), 620, 1e-12);
  EXPECT_NEAR(pixel->y(), 740, 1e-12);
  // Back: mx = 0.625, my = 5/6, r² = 1.0850694…; beta·r² = 0.390625, the root is
  // sqrt(1 − 0.6·0.390625) = 0.875, mz = (1 − 0.64·0.390625) / (0.8·0.875 + 0.2) = 5/6, and the
  // ray (mx/mz, my/mz, 1) = (0.75, 1, 1) = (3, 4, 4)/4.
  auto ray = camera.unproject({620, 740});
  ASSERT_TRUE(ray);
  EXPECT_NEAR(ray->x(), 0.75, 1e-12);
  EXPECT_NEAR(ray->y(), 1.0, 1e-12);
  EXPECT_EQ(ray->z(), 1.0);
  EXPECT_EQ(camera.type(), "eucm");
  EXPECT_EQ(camera.width(), 1280);
  EXPECT_EQ(camera.height(), 960);
}

TEST(EucmCamera, EveryPixelOfTheImageUnprojectsAndProjectsBack) {
  for (const EucmCamera* camera : {&kMildLens, &kWideLens, &kFisheye}) {
    int pixels = 0;
    double worst = 0;
    for (int v = 0; v < camera->height(); v += 17) {
      for (int u = 0; u < camera->width(); u += 17) {
        Eigen::Vector2d pixel(u, v);
        auto ray = camera->unproject(pixel);
        ASSERT_TRUE(ray) << "alpha " << camera->alpha() << ", pixel " << u << ", " << v;
        auto back = camera->project(*ray);
        ASSERT_TRUE(back);
        worst = std::max(worst, (*back - pixel).norm());
        ++pixels;
      }
    }
    EXPECT_LT(worst, 1e-9) << "alpha " << camera->alpha() << " over " << pixels << " pixels";
  }
}

TEST(EucmCamera, RaysUpToNinetyDegreesProjectAndUnprojectBack) {
  for (const EucmCamera* camera : {&kMildLens, &kWideLens, &kFisheye}) {
    double worst = 0;
    for (double angle = 0; angle <= 89.5 * kDeg; angle += 2.5 * kDeg) {
      for (double azimuth = 0; azimuth < 2 * std::numbers::pi; azimuth += 20 * kDeg) {
        Eigen::Vector3d ray(std::sin(angle) * std::cos(azimuth),
                            std::sin(angle) * std::sin(azimuth), std::cos(angle));
        auto pixel = camera->project(2.7 * ray);
        ASSERT_TRUE(pixel) << angle / kDeg << " deg";
        auto back = camera->unproject(*pixel);
        ASSERT_TRUE(back) << angle / kDeg << " deg";
        worst = std::max(worst, (back->normalized() - ray).norm());
      }
    }
    EXPECT_LT(worst, 1e-9) << "alpha " << camera->alpha();
  }
  // What the lenses are for: the fisheye's corners look far further out than the mild lens's.
  auto corner_angle = [](const EucmCamera& camera) {
    auto ray = camera.unproject({0, 0});
    return ray ? std::atan(ray->head<2>().norm()) / kDeg : -1.0;
  };
  EXPECT_LT(corner_angle(kMildLens), 30);
  EXPECT_GT(corner_angle(kFisheye), 70);
}

TEST(EucmCamera, BeyondNinetyDegreesAFisheyeProjectsButTheRayCannotBeExpressed) {
  // 95 degrees off the axis: z < 0, still on the valid side of the ellipsoid; its pixel lies
  // beyond that of 90 degrees and maps back to no (x/z, y/z, 1) ray.
  Eigen::Vector3d point(std::sin(95 * kDeg), 0, std::cos(95 * kDeg));
  auto pixel = kFisheye.project(point);
  ASSERT_TRUE(pixel);
  EXPECT_GT(pixel->x(), kFisheye.project({1, 0, 1e-9})->x());
  EXPECT_FALSE(kFisheye.unproject(*pixel));
  // 120 degrees is past the validity boundary (z > −rho/9 for alpha 0.9).
  EXPECT_FALSE(kFisheye.project({std::sin(120 * kDeg), 0, std::cos(120 * kDeg)}));
}

TEST(EucmCamera, ProjectionStopsAtTheModelsValidityBoundary) {
  constexpr double eps = 1e-9;
  // alpha 0.8, beta 1: w = 0.25; on the ray (1, 0, z) the boundary z = −0.25·sqrt(1 + z²) is
  // z = −1/sqrt(15).
  EucmCamera wide(1024, 768, {0.8, 1.0, 300, 300, 512, 384});
  double boundary = -1 / std::sqrt(15.0);
  EXPECT_TRUE(wide.project({1, 0, boundary + eps}));
  EXPECT_FALSE(wide.project({1, 0, boundary - eps}));
  // alpha 0.3, beta 1.5: w = 3/7, the boundary is where d = 0: z = −w·sqrt(beta/(1 − w²)).
  EucmCamera mild(1024, 768, {0.3, 1.5, 300, 300, 512, 384});
  double w = 0.3 / 0.7;
  boundary = -w * std::sqrt(1.5 / (1 - w * w));
  EXPECT_TRUE(mild.project({1, 0, boundary + eps}));
  EXPECT_FALSE(mild.project({1, 0, boundary - eps}));
  // alpha 0 and 1: only what is in front.
  for (double alpha : {0.0, 1.0}) {
    EucmCamera camera(1024, 768, {alpha, 1.0, 300, 300, 512, 384});
    EXPECT_TRUE(camera.project({1, 0, 1e-6})) << alpha;
    EXPECT_FALSE(camera.project({1, 0, 0})) << alpha;
    EXPECT_FALSE(camera.project({1, 0, -1e-6})) << alpha;
  }
  EXPECT_FALSE(wide.project({0, 0, 0}));
}

TEST(EucmCamera, UnprojectionStopsAtNinetyDegreesAndOutsideTheValidDisc) {
  // alpha 0.8, beta 1, fu = fv = 100 at (0, 0): mz = 0 where beta·alpha²·r² = 1, r = 1.25
  // (125 pixels); the valid disc ends at r² = 1/(beta·(2·alpha − 1)), r = 1.29 (129 pixels).
  EucmCamera camera(1024, 768, {0.8, 1.0, 100, 100, 0, 0});
  auto inside = camera.unproject({124.99, 0});
  ASSERT_TRUE(inside);
  EXPECT_GT(inside->x(), 100);  // nearly 90 degrees
  EXPECT_FALSE(camera.unproject({125.01, 0}));
  EXPECT_FALSE(camera.unproject({0, -127}));
  EXPECT_FALSE(camera.unproject({200, 300}));  // outside the disc: no square root of < 0
  // alpha 0.3 has no disc limit, only the 90 degrees: r = 1/(alpha·sqrt(beta)) = 10/3.
  EucmCamera mild(1024, 768, {0.3, 1.0, 100, 100, 0, 0});
  EXPECT_TRUE(mild.unproject({333.3, 0}));
  EXPECT_FALSE(mild.unproject({333.4, 0}));
  EXPECT_FALSE(mild.unproject({5000, 5000}));
}

TEST(EucmCamera, AlphaZeroIsAPinholeWhateverBeta) {
  PinholeIntrinsics k;
  k.fx = 800;
  k.fy = 790;
  k.cx = 500;
  k.cy = 380;
  PinholeCamera pinhole(1024, 768, k);
  for (double beta : {0.2, 1.0, 7.0}) {
    EucmCamera camera(1024, 768, {0.0, beta, 800, 790, 500, 380});
    for (const Eigen::Vector3d& point :
         {Eigen::Vector3d(0.3, -0.2, 1.5), Eigen::Vector3d(-2, 1, 0.5), Eigen::Vector3d(0, 0, 3)}) {
      auto a = camera.project(point);
      auto b = pinhole.project(point);
      ASSERT_TRUE(a && b);
      EXPECT_NEAR((*a - *b).norm(), 0, 1e-9) << beta;
    }
    auto ray = camera.unproject({900, 100});
    ASSERT_TRUE(ray);
    EXPECT_NEAR(ray->x(), 0.5, 1e-12);
    EXPECT_NEAR(ray->y(), -280.0 / 790, 1e-12);
  }
}

TEST(EucmCamera, FocalLengthIsThePixelsPerRadianAtTheCentre) {
  for (const EucmCamera* camera : {&kMildLens, &kWideLens, &kFisheye}) {
    const auto& p = camera->parameters();
    double angle = 1e-5;
    auto u = camera->project({std::sin(angle), 0, std::cos(angle)});
    auto v = camera->project({0, std::sin(angle), std::cos(angle)});
    ASSERT_TRUE(u && v);
    EXPECT_NEAR((u->x() - p[4]) / angle, p[2], 1e-4) << camera->alpha();
    EXPECT_NEAR((v->y() - p[5]) / angle, p[3], 1e-4) << camera->alpha();
    EXPECT_DOUBLE_EQ(camera->focal_length_px(), 0.5 * (p[2] + p[3]));
  }
  // Away from the centre a fisheye's scale shrinks: 60 degrees lie well inside fu·tan(60°).
  auto pixel = kFisheye.project({std::sin(60 * kDeg), 0, std::cos(60 * kDeg)});
  ASSERT_TRUE(pixel);
  const auto& p = kFisheye.parameters();
  EXPECT_LT(pixel->x() - p[4], 0.7 * p[2] * std::tan(60 * kDeg));
}

TEST(EucmCamera, RejectsParametersOutsideTheModel) {
  std::array<double, 6> good = {0.5, 1, 300, 300, 512, 384};
  EXPECT_NO_THROW(EucmCamera(1024, 768, good));
  EXPECT_NO_THROW(EucmCamera(1024, 768, {0, 1, 300, 300, 512, 384}));
  EXPECT_NO_THROW(EucmCamera(1024, 768, {1, 1, 300, 300, 512, 384}));
  auto with = [&](size_t index, double value) {
    std::array<double, 6> p = good;
    p[index] = value;
    return error_of([&] { EucmCamera(1024, 768, p); });
  };
  EXPECT_TRUE(contains(with(0, -0.01), "alpha must be in [0, 1]")) << with(0, -0.01);
  EXPECT_TRUE(contains(with(0, 1.01), "alpha must be in [0, 1]"));
  EXPECT_TRUE(contains(with(1, 0), "beta must be positive"));
  EXPECT_TRUE(contains(with(1, -1), "beta must be positive"));
  EXPECT_TRUE(contains(with(2, 0), "focal lengths"));
  EXPECT_TRUE(contains(with(3, -300), "focal lengths"));
  EXPECT_TRUE(contains(with(4, NAN), "not finite"));
  EXPECT_TRUE(contains(error_of([&] { EucmCamera(0, 768, good); }), "image size"));
  EXPECT_THROW(EucmCamera(1024, -1, good), std::invalid_argument);
}

TEST(EucmCamera, CloneIsTheSameCamera) {
  std::unique_ptr<CameraModel> copy = kWideLens.clone();
  ASSERT_EQ(copy->type(), "eucm");
  EXPECT_EQ(dynamic_cast<const EucmCamera&>(*copy).parameters(), kWideLens.parameters());
  EXPECT_EQ(*copy->project({0.3, 0.2, 1}), *kWideLens.project({0.3, 0.2, 1}));
}

// ---------------------------------------------------------------------------------------------
// The pinhole, now through pinhole_project.

TEST(PinholeCamera, ProjectsAPointWorkedOutByHand) {
  // k1 0.1, p1 0.01; (0.2, 0.1, 1): r² = 0.05, radial 1.005; x' = 0.201 + 2·0.01·0.02 = 0.2014,
  // y' = 0.1005 + 0.01·(0.05 + 0.02) = 0.1012; u = 500·0.2014 + 320, v = 400·0.1012 + 240.
  PinholeIntrinsics k{500, 400, 320, 240, {0.1, 0, 0.01, 0, 0}};
  PinholeCamera camera(640, 480, k);
  auto pixel = camera.project({0.4, 0.2, 2});
  ASSERT_TRUE(pixel);
  EXPECT_NEAR(pixel->x(), 420.7, 1e-12);
  EXPECT_NEAR(pixel->y(), 280.48, 1e-12);
  EXPECT_FALSE(camera.project({0.4, 0.2, 0}));
  EXPECT_FALSE(camera.project({0.4, 0.2, -1}));
  auto ray = camera.unproject(*pixel);
  ASSERT_TRUE(ray);
  EXPECT_NEAR(ray->x(), 0.2, 1e-9);
  EXPECT_NEAR(ray->y(), 0.1, 1e-9);
  const std::array<double, 9> expected = {500, 400, 320, 240, 0.1, 0, 0.01, 0, 0};
  EXPECT_EQ(camera.parameters(), expected);
}

// ---------------------------------------------------------------------------------------------
// The lens formulas with Ceres Jets: the calibration's derivatives.

// Checks `project` (a lens model of N parameters) at `parameters` and `point`: the Jet values
// equal the double ones, and the Jet derivatives with respect to every parameter and point
// coordinate match central differences.
template <int N, class Project>
void check_derivatives(Project project, const std::array<double, N>& parameters,
                       const Eigen::Vector3d& point) {
  constexpr int kInputs = N + 3;
  using Jet = ceres::Jet<double, kInputs>;
  std::array<Jet, N> jet_parameters;
  for (int i = 0; i < N; ++i) jet_parameters[i] = Jet(parameters[i], i);
  std::array<Jet, 3> jet_point;
  for (int i = 0; i < 3; ++i) jet_point[i] = Jet(point[i], N + i);
  std::array<Jet, 2> jet_pixel;
  ASSERT_TRUE(project(jet_parameters.data(), jet_point.data(), jet_pixel.data()));
  std::array<double, 2> pixel;
  ASSERT_TRUE(project(parameters.data(), point.data(), pixel.data()));
  for (int k = 0; k < 2; ++k) {
    EXPECT_NEAR(jet_pixel[k].a, pixel[k], 1e-13 * std::max(1.0, std::abs(pixel[k])));
  }
  // Input i of all of them, moved by h.
  auto evaluate = [&](int i, double h) {
    std::array<double, N> p = parameters;
    Eigen::Vector3d x = point;
    if (i < N) {
      p[i] += h;
    } else {
      x[i - N] += h;
    }
    std::array<double, 2> out;
    EXPECT_TRUE(project(p.data(), x.data(), out.data()));
    return out;
  };
  for (int i = 0; i < kInputs; ++i) {
    double value = i < N ? parameters[i] : point[i - N];
    double h = 1e-5 * std::max(1.0, std::abs(value));
    std::array<double, 2> plus = evaluate(i, h), minus = evaluate(i, -h);
    for (int k = 0; k < 2; ++k) {
      double numeric = (plus[k] - minus[k]) / (2 * h);
      double automatic = jet_pixel[k].v[i];
      EXPECT_NEAR(automatic, numeric, 1e-6 * std::max(1.0, std::abs(numeric)))
          << "d pixel[" << k << "] / d input " << i;
    }
  }
}

struct Eucm {
  template <class T>
  bool operator()(const T* parameters, const T* point, T* pixel) const {
    return eucm_project(parameters, point, pixel);
  }
};

struct Pinhole {
  template <class T>
  bool operator()(const T* parameters, const T* point, T* pixel) const {
    return pinhole_project(parameters, point, pixel);
  }
};

TEST(LensModels, EucmJetsMatchDoublesAndFiniteDifferences) {
  const std::vector<std::array<double, kEucmParameters>> lenses = {
      {0.3, 1.1, 1300, 1310, 511.5, 383.5},
      {0.62, 1.05, 420, 425, 515, 380},
      {0.9, 0.85, 560, 560, 511.5, 383.5},
      {0.0, 1.0, 600, 600, 320, 240}};
  for (const auto& lens : lenses) {
    SCOPED_TRACE(testing::Message() << "alpha " << lens[0]);
    check_derivatives<kEucmParameters>(Eucm{}, lens, {0.31, -0.22, 1.4});
    check_derivatives<kEucmParameters>(Eucm{}, lens, {-1.2, 0.7, 0.9});
    check_derivatives<kEucmParameters>(Eucm{}, lens, {0.0, 0.0, 2.0});
  }
  // Behind a fisheye, still valid.
  check_derivatives<kEucmParameters>(Eucm{}, lenses[2], {1.0, 0.3, -0.1});
}

TEST(LensModels, PinholeJetsMatchDoublesAndFiniteDifferences) {
  const std::array<double, kPinholeParameters> lens = {812,  805,   640.5,   359.5, -0.28,
                                                       0.09, 0.001, -0.0005, 0.02};
  check_derivatives<kPinholeParameters>(Pinhole{}, lens, {0.31, -0.22, 1.4});
  check_derivatives<kPinholeParameters>(Pinhole{}, lens, {-0.5, 0.4, 1.0});
  check_derivatives<kPinholeParameters>(Pinhole{}, lens, {0.0, 0.0, 3.0});
}

TEST(LensModels, JetsAreRejectedWhereDoublesAre) {
  using Jet = ceres::Jet<double, 3>;
  const std::array<Jet, 6> eucm_parameters = {Jet(0.8), Jet(1.0), Jet(300),
                                              Jet(300), Jet(512), Jet(384)};
  const std::array<Jet, 9> pinhole_parameters = {Jet(300), Jet(300), Jet(512), Jet(384), Jet(0),
                                                 Jet(0),   Jet(0),   Jet(0),   Jet(0)};
  std::array<Jet, 2> pixel = {Jet(-7), Jet(-7)};
  double boundary = -1 / std::sqrt(15.0);  // see ProjectionStopsAtTheModelsValidityBoundary
  std::array<Jet, 3> outside = {Jet(1, 0), Jet(0, 1), Jet(boundary - 1e-9, 2)};
  std::array<Jet, 3> inside = {Jet(1, 0), Jet(0, 1), Jet(boundary + 1e-9, 2)};
  EXPECT_FALSE(eucm_project(eucm_parameters.data(), outside.data(), pixel.data()));
  EXPECT_EQ(pixel[0].a, -7);  // untouched
  EXPECT_TRUE(eucm_project(eucm_parameters.data(), inside.data(), pixel.data()));
  EXPECT_FALSE(pinhole_project(pinhole_parameters.data(), inside.data(), pixel.data()));
  std::array<Jet, 3> in_front = {Jet(1, 0), Jet(0, 1), Jet(1e-9, 2)};
  EXPECT_TRUE(pinhole_project(pinhole_parameters.data(), in_front.data(), pixel.data()));
}

// ---------------------------------------------------------------------------------------------
// Unified cameras (UCM and Mei).

struct Ucm {
  template <class T>
  bool operator()(const T* parameters, const T* point, T* pixel) const {
    return ucm_project(parameters, point, pixel);
  }
};

struct Mei {
  template <class T>
  bool operator()(const T* parameters, const T* point, T* pixel) const {
    return mei_project(parameters, point, pixel);
  }
};

// Directions every 7.5 degrees over the whole sphere but the poles.
std::vector<Eigen::Vector3d> directions_all_round() {
  std::vector<Eigen::Vector3d> directions;
  for (double polar = 7.5; polar < 180; polar += 7.5) {
    for (double azimuth = 0; azimuth < 360; azimuth += 15) {
      directions.emplace_back(std::sin(polar * kDeg) * std::cos(azimuth * kDeg),
                              std::sin(polar * kDeg) * std::sin(azimuth * kDeg),
                              std::cos(polar * kDeg));
    }
  }
  return directions;
}

// The UCM is the EUCM with a sphere (beta = 1), alpha = xi / (1 + xi) and focal lengths divided
// by 1 + xi: the same pixels and the same valid region, whatever side of xi = 1.
TEST(UnifiedCamera, UcmIsEucmWithASphere) {
  for (double xi : {0.0, 0.4, 1.0, 1.7}) {
    SCOPED_TRACE(testing::Message() << "xi " << xi);
    const std::array<double, kUcmParameters> ucm = {xi, 700, 710, 320.5, 240.5};
    const std::array<double, kEucmParameters> eucm = {xi / (1 + xi),  1,     700 / (1 + xi),
                                                      710 / (1 + xi), 320.5, 240.5};
    int valid = 0;
    for (const Eigen::Vector3d& direction : directions_all_round()) {
      const Eigen::Vector3d point = 2.5 * direction;
      std::array<double, 2> a{}, b{};
      const bool in_ucm = ucm_project(ucm.data(), point.data(), a.data());
      ASSERT_EQ(in_ucm, eucm_project(eucm.data(), point.data(), b.data())) << point.transpose();
      if (!in_ucm) continue;
      ++valid;
      EXPECT_NEAR(a[0], b[0], 1e-9 * std::max(1.0, std::abs(b[0])));
      EXPECT_NEAR(a[1], b[1], 1e-9 * std::max(1.0, std::abs(b[1])));
    }
    EXPECT_GT(valid, 100);
  }
}

// Against OpenCV's omnidirectional camera (cv::omnidir, Mei's model with k1, k2, p1, p2), an
// implementation of its own: visgeom's k3 is 0 there, its k4 and k5 are OpenCV's p1 and p2.
TEST(UnifiedCamera, MeiAgreesWithOpenCVsOmnidirectionalCamera) {
  const double xi = 1.15, k1 = -0.18, k2 = 0.04, p1 = 0.0012, p2 = -0.0007;
  const std::array<double, kMeiParameters> mei = {xi, k1, k2, 0, p1, p2, 780, 776, 321.5, 243.0};
  std::vector<cv::Point3d> points;
  for (const Eigen::Vector3d& direction : directions_all_round()) {
    if (direction.z() > std::cos(100 * kDeg)) {
      points.emplace_back(3 * direction.x(), 3 * direction.y(), 3 * direction.z());
    }
  }
  std::vector<cv::Point2d> expected;
  const cv::Matx33d k(780, 0, 321.5, 0, 776, 243.0, 0, 0, 1);
  cv::omnidir::projectPoints(points, expected, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), k, xi,
                             cv::Vec4d(k1, k2, p1, p2));
  ASSERT_EQ(expected.size(), points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d point(points[i].x, points[i].y, points[i].z);
    std::array<double, 2> pixel;
    ASSERT_TRUE(mei_project(mei.data(), point.data(), pixel.data())) << point.transpose();
    EXPECT_NEAR(pixel[0], expected[i].x, 1e-9) << point.transpose();
    EXPECT_NEAR(pixel[1], expected[i].y, 1e-9) << point.transpose();
  }
}

TEST(UnifiedCamera, EveryPixelOfTheImageUnprojectsAndProjectsBack) {
  const std::vector<double> ucm = {0.8, 610, 615, 320.5, 240.5};
  const std::vector<double> narrow_ucm = {1.6, 1500, 1500, 320.5, 240.5};
  const std::vector<double> mei = {0.95, -0.12, 0.03, -0.004, 0.0011, -0.0006, 640, 642, 318, 243};
  for (const std::vector<double>* parameters : {&ucm, &narrow_ucm, &mei}) {
    const UnifiedCamera camera(640, 480, *parameters);
    SCOPED_TRACE(camera.type());
    int pixels = 0;
    double worst = 0;
    for (int v = 0; v < camera.height(); v += 7) {
      for (int u = 0; u < camera.width(); u += 7) {
        const Eigen::Vector2d pixel(u, v);
        auto ray = camera.unproject(pixel);
        ASSERT_TRUE(ray) << pixel.transpose();
        auto back = camera.project(*ray);
        ASSERT_TRUE(back) << pixel.transpose();
        worst = std::max(worst, (*back - pixel).norm());
        ++pixels;
      }
    }
    EXPECT_GT(pixels, 6000);
    EXPECT_LT(worst, 1e-8);
  }
}

// xi = 2: w = 1/2, the valid region ends 120 degrees from the axis (z = −rho / 2); the pixels
// of points beyond it would fold back over those of valid ones.
TEST(UnifiedCamera, ProjectionStopsAtTheModelsValidityBoundary) {
  const UnifiedCamera ucm(640, 480, std::vector<double>{2, 900, 900, 320, 240});
  const UnifiedCamera mei(640, 480,
                          std::vector<double>{2, -0.1, 0.01, 0, 0.001, 0.001, 900, 900, 320, 240});
  for (const UnifiedCamera* camera : {&ucm, &mei}) {
    const double inside = 120 * kDeg - 1e-6, outside = 120 * kDeg + 1e-6;
    EXPECT_TRUE(camera->project({std::sin(inside), 0, std::cos(inside)})) << camera->type();
    EXPECT_FALSE(camera->project({std::sin(outside), 0, std::cos(outside)})) << camera->type();
    EXPECT_FALSE(camera->project({0, 0, -1})) << camera->type();
  }
  // 90 degrees from the axis is r = 1/2 here (1 + (1 − xi²)·r² = xi²·r⁴): a ray (x/z, y/z, 1)
  // ends there, short of the valid disc's edge (r² = 1 / (xi² − 1)).
  auto ray = ucm.unproject({320 + 450 - 1e-3, 240});
  ASSERT_TRUE(ray);
  EXPECT_GT(ray->x(), 1e4);
  EXPECT_FALSE(ucm.unproject({320 + 450 + 1e-3, 240}));
  EXPECT_FALSE(ucm.unproject({320 + std::sqrt(1.0 / 3) * 900 + 1, 240}));
}

TEST(UnifiedCamera, FocalLengthIsThePixelsPerRadianAtTheCentre) {
  const UnifiedCamera camera(640, 480, std::vector<double>{0.9, 760, 770, 320, 240});
  const double angle = 1e-4;
  auto pixel = camera.project({std::tan(angle), 0, 1});
  ASSERT_TRUE(pixel);
  EXPECT_NEAR((pixel->x() - 320) / angle, 760 / 1.9, 1e-3);
  EXPECT_NEAR(camera.focal_length_px(), 765 / 1.9, 1e-12);
}

TEST(UnifiedCamera, RejectsParametersOutsideTheModel) {
  auto error = [](std::vector<double> parameters) {
    return error_of([&] { UnifiedCamera(640, 480, parameters); });
  };
  EXPECT_EQ(error({-0.1, 700, 700, 320, 240}), "ucm camera: xi must not be negative");
  EXPECT_EQ(error({0.5, 700, 0, 320, 240}), "ucm camera: focal lengths fu, fv must be positive");
  EXPECT_EQ(error({0.5, 0, 0, 0, 0, 0, -700, 700, 320, 240}),
            "mei camera: focal lengths fu, fv must be positive");
  EXPECT_EQ(error({0.5, NAN, 0, 0, 0, 0, 700, 700, 320, 240}),
            "mei camera: a parameter is not finite");
  EXPECT_EQ(error({0.5, 700, 700, 320}), "unified camera: 5 parameters (ucm) or 10 (mei), not 4");
}

TEST(LensModels, UcmAndMeiJetsMatchDoublesAndFiniteDifferences) {
  for (double xi : {0.3, 0.95, 1.6}) {
    SCOPED_TRACE(testing::Message() << "xi " << xi);
    const std::array<double, kUcmParameters> ucm = {xi, 700, 710, 320.5, 240.5};
    const std::array<double, kMeiParameters> mei = {xi,      -0.15, 0.03, -0.002, 0.0012,
                                                    -0.0007, 700,   710,  320.5,  240.5};
    for (const Eigen::Vector3d& point :
         {Eigen::Vector3d(0.31, -0.22, 1.4), Eigen::Vector3d(-1.2, 0.7, 0.9),
          Eigen::Vector3d(0.9, 0.2, -0.1)}) {
      check_derivatives<kUcmParameters>(Ucm{}, ucm, point);
      check_derivatives<kMeiParameters>(Mei{}, mei, point);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// The factory.

TEST(CameraFactory, MakesModelsFromTheirParametersAndGivesThemBack) {
  const std::vector<double> eucm = {0.6, 1.1, 1175, 1180, 512, 384};
  auto camera = make_camera_model("eucm", 1024, 768, eucm);
  ASSERT_EQ(camera->type(), "eucm");
  EXPECT_EQ(camera->width(), 1024);
  EXPECT_EQ(camera->height(), 768);
  EXPECT_EQ(camera_parameters(*camera), eucm);

  const std::vector<double> short_pinhole = {800, 810, 640, 360};
  camera = make_camera_model("pinhole", 1280, 720, short_pinhole);
  ASSERT_EQ(camera->type(), "pinhole");
  EXPECT_EQ(camera_parameters(*camera), (std::vector<double>{800, 810, 640, 360, 0, 0, 0, 0, 0}));
  const std::vector<double> full = {800, 810, 640, 360, -0.2, 0.05, 0.001, 0.002, -0.01};
  camera = make_camera_model("pinhole", 1280, 720, full);
  EXPECT_EQ(camera_parameters(*camera), full);
  auto pixel = camera->project({0.1, 0.2, 1});
  std::array<double, 2> expected;
  Eigen::Vector3d point(0.1, 0.2, 1);
  ASSERT_TRUE(pinhole_project(full.data(), point.data(), expected.data()));
  EXPECT_EQ(pixel->x(), expected[0]);
  EXPECT_EQ(pixel->y(), expected[1]);
}

TEST(CameraFactory, NamesTheTypeAndTheCountItExpects) {
  const std::vector<double> five = {1, 1, 300, 300, 512};
  std::string error = error_of([&] { make_camera_model("eucm", 1024, 768, five); });
  EXPECT_EQ(error, "eucm takes 6 numbers (alpha, beta, fu, fv, u0, v0), not 5");
  error = error_of([&] { make_camera_model("pinhole", 1024, 768, five); });
  EXPECT_EQ(error, "pinhole takes 4 or 9 numbers (fx, fy, cx, cy, then k1, k2, p1, p2, k3), not 5");
  error = error_of([&] { make_camera_model("mei", 1024, 768, five); });
  EXPECT_EQ(error, "mei takes 10 numbers (xi, k1, k2, k3, k4, k5, fu, fv, u0, v0), not 5");
  EXPECT_NO_THROW(make_camera_model("ucm", 1024, 768, five));
  error = error_of([&] { make_camera_model("fisheye", 1024, 768, five); });
  EXPECT_EQ(error, "unknown camera type 'fisheye' (eucm, mei, pinhole, ucm)");
  const std::vector<double> bad_beta = {0.5, 0, 300, 300, 512, 384};
  EXPECT_THROW(make_camera_model("eucm", 1024, 768, bad_beta), std::invalid_argument);

  struct Unknown : CameraModel {
    std::string type() const override { return "orthographic"; }
    int width() const override { return 1; }
    int height() const override { return 1; }
    std::optional<Eigen::Vector2d> project(const Eigen::Vector3d&) const override { return {}; }
    std::optional<Eigen::Vector3d> unproject(const Eigen::Vector2d&) const override { return {}; }
    double focal_length_px() const override { return 1; }
    std::unique_ptr<CameraModel> clone() const override { return nullptr; }
  };
  error = error_of([] { camera_parameters(Unknown{}); });
  EXPECT_TRUE(contains(error, "'orthographic'")) << error;
}

// ---------------------------------------------------------------------------------------------
// Camera files.

Eigen::Isometry3d some_pose() {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(2.9, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).matrix();
  pose.translation() = Eigen::Vector3d(0.1 + 0.2, -1.0 / 3, 2.5);
  return pose;
}

void expect_same_pose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  EXPECT_LT((a.matrix() - b.matrix()).cwiseAbs().maxCoeff(), 1e-15) << a.matrix() << "\n"
                                                                    << b.matrix();
  EXPECT_EQ(a.translation(), b.translation());
}

TEST(CameraFile, EucmAndPoseGoThroughTheWriterAndBack) {
  test::TempDir dir;
  CameraFile camera;
  camera.name = "camera2";
  camera.frame_id = "pixart_camera2_optical";
  // Values that need all 17 digits.
  camera.model =
      std::make_shared<EucmCamera>(1024, 768,
                                   std::array<double, 6>{0.1 + 0.2, 1.0 / 3, 1175.0 / 0.7,
                                                         1180.123456789012, 511.5, 383.5 + 1e-9});
  camera.world_from_camera = some_pose();
  std::string path = (dir / "camera2.yaml").string();
  save_camera_file(path, camera);
  std::string text = test::read_file(path);
  EXPECT_TRUE(contains(text, "distortion_model: eucm")) << text;
  EXPECT_TRUE(text.starts_with("# ")) << text;
  EXPECT_FALSE(std::filesystem::exists(path + ".partial"));

  CameraFile loaded = load_camera_file(path);
  EXPECT_EQ(loaded.name, "camera2");
  EXPECT_EQ(loaded.frame_id, "pixart_camera2_optical");
  ASSERT_EQ(loaded.model->type(), "eucm");
  EXPECT_EQ(loaded.model->width(), 1024);
  EXPECT_EQ(loaded.model->height(), 768);
  EXPECT_EQ(camera_parameters(*loaded.model), camera_parameters(*camera.model));
  ASSERT_TRUE(loaded.world_from_camera);
  expect_same_pose(*loaded.world_from_camera, *camera.world_from_camera);
}

TEST(CameraFile, UcmAndMeiGoThroughTheWriterAndBack) {
  test::TempDir dir;
  for (const std::vector<double>& parameters :
       {std::vector<double>{0.1 + 0.2, 700.0 / 3, 701, 320.5, 240.5},
        std::vector<double>{1.0 / 3, -0.1, 0.02, -0.003, 1e-4, -2e-4, 700, 701, 320.5, 240.5}}) {
    CameraFile camera;
    camera.name = "omni";
    camera.model = make_camera_model(parameters.size() == 5 ? "ucm" : "mei", 640, 480, parameters);
    const std::string path = (dir / "omni.yaml").string();
    save_camera_file(path, camera);
    const std::string text = test::read_file(path);
    EXPECT_TRUE(contains(text, "distortion_model: " + camera.model->type())) << text;
    const CameraFile loaded = load_camera_file(path);
    ASSERT_EQ(loaded.model->type(), camera.model->type());
    EXPECT_EQ(camera_parameters(*loaded.model), parameters);
  }
  const CameraFile visgeom_names = parse_camera_file(
      "camera_name: c\nimage_width: 640\nimage_height: 480\n"
      "distortion_model: mei\nmei: {xi: 0.9, k1: -0.1, k2: 0.02, k3: 0, "
      "k4: 0.001, k5: -0.0005, fu: 760, fv: 761, u0: 320, v0: 240}\n",
      "omni.yaml");
  EXPECT_EQ(camera_parameters(*visgeom_names.model),
            (std::vector<double>{0.9, -0.1, 0.02, 0, 0.001, -0.0005, 760, 761, 320, 240}));
}

TEST(CameraFile, PinholeKeepsTheCameraInfoLayoutAndGoesThroughTheWriterAndBack) {
  test::TempDir dir;
  CameraFile camera;
  camera.name = "ir";
  camera.frame_id = "ir";
  PinholeIntrinsics k{812.25 + 1e-10, 805.5, 640.5, 359.5, {-0.28, 0.09, 0.001, -0.0005, 0.1 / 3}};
  camera.model = std::make_shared<PinholeCamera>(1280, 720, k);
  std::string path = (dir / "ir.yaml").string();
  save_camera_file(path, camera);
  std::string text = test::read_file(path);
  for (const char* field :
       {"image_width: 1280", "distortion_model: plumb_bob", "camera_matrix:",
        "distortion_coefficients:", "rectification_matrix:", "projection_matrix:"}) {
    EXPECT_TRUE(contains(text, field)) << field << " in\n" << text;
  }
  EXPECT_FALSE(contains(text, "frame_id")) << text;  // the same as the name
  EXPECT_FALSE(contains(text, "pose")) << text;
  CameraFile loaded = load_camera_file(path);
  EXPECT_EQ(loaded.name, "ir");
  EXPECT_EQ(loaded.frame_id, "ir");
  ASSERT_EQ(loaded.model->type(), "pinhole");
  EXPECT_EQ(camera_parameters(*loaded.model), camera_parameters(*camera.model));
  EXPECT_FALSE(loaded.world_from_camera);

  camera.world_from_camera = some_pose();
  camera.name = "yes";  // a YAML boolean unless quoted
  save_camera_file(path, camera);
  loaded = load_camera_file(path);
  EXPECT_EQ(loaded.name, "yes");
  ASSERT_TRUE(loaded.world_from_camera);
  expect_same_pose(*loaded.world_from_camera, *camera.world_from_camera);
}

TEST(CameraFile, ReadsAHandWrittenPoseAndNormalisesItsQuaternion) {
  CameraFile camera = parse_camera_file(R"(camera_name: camera0
image_width: 1024
image_height: 768
distortion_model: eucm
eucm: {alpha: 0.6, beta: 1.1, fu: 1175, fv: 1175, u0: 512, v0: 384}
pose: {translation: [0.5, 0.5, 2.5], rotation: [0, 0, 0.7071, 0.7071]}
)",
                                        "camera0.yaml");
  EXPECT_EQ(camera_parameters(*camera.model),
            (std::vector<double>{0.6, 1.1, 1175, 1175, 512, 384}));
  ASSERT_TRUE(camera.world_from_camera);
  // A quarter turn about z: camera x along world y.
  const Eigen::Isometry3d& pose = *camera.world_from_camera;
  EXPECT_LT((pose.linear() * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 1e-12);
  EXPECT_LT((pose.linear().transpose() * pose.linear() - Eigen::Matrix3d::Identity()).norm(),
            1e-15);
  EXPECT_EQ(pose.translation(), Eigen::Vector3d(0.5, 0.5, 2.5));
}

TEST(CameraFile, BadFieldsAreNamedWithFileAndLine) {
  const std::string head = "camera_name: c\nimage_width: 1024\nimage_height: 768\n";
  auto error = [&](const std::string& rest) {
    return error_of([&] { parse_camera_file(head + rest, "cam.yaml"); });
  };
  const std::string eucm = "distortion_model: eucm\n";  // line 4
  struct Case {
    std::string rest;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {eucm, "cam.yaml:1: a camera file needs 'eucm'"},
      {eucm + "eucm:\n  alpha: 0.5\n  fu: 300\n  fv: 300\n  u0: 1\n  v0: 2\n",
       "cam.yaml:6: 'eucm' needs 'beta'"},
      {eucm + "eucm:\n  alpha: 0.5\n  beta: wide\n  fu: 300\n  fv: 300\n  u0: 1\n  v0: 2\n",
       "cam.yaml:7: 'eucm.beta' must be a number, not 'wide'"},
      {eucm + "eucm:\n  alpha: 0.5\n  beta: 1\n  fu: 300\n  fv: 300\n  u0: 1\n  v0: 2\n"
              "  gamma: 3\n",
       "cam.yaml:12: unknown key 'gamma' in 'eucm'"},
      {eucm + "eucm:\n  alpha: 1.5\n  beta: 1\n  fu: 300\n  fv: 300\n  u0: 1\n  v0: 2\n",
       "cam.yaml:6: eucm camera: alpha must be in [0, 1]"},
      {eucm + "eucm: [0.5, 1, 300, 300, 1, 2]\n",
       "cam.yaml:5: 'eucm' must be a map, not a list of 6"},
      {"distortion_model: kannala_brandt\n",
       "cam.yaml:4: distortion_model 'kannala_brandt' is not supported (plumb_bob, pinhole, eucm, "
       "mei, ucm)"},
      {"distortion_model: mei\nmei: {xi: 0.9, k1: 0, k2: 0, k4: 0, k5: 0, fu: 300, fv: 300, u0: 1, "
       "v0: 2}\n",
       "cam.yaml:5: 'mei' needs 'k3'"},
      {"distortion_model: ucm\nucm: {xi: -0.1, fu: 300, fv: 300, u0: 1, v0: 2}\n",
       "cam.yaml:5: ucm camera: xi must not be negative"},
      {eucm + "eucm: {alpha: 0.5, beta: 1, fu: 300, fv: 300, u0: 1, v0: 2}\n" +
           "pose:\n  translation: [1, 2]\n  rotation: [0, 0, 0, 1]\n",
       "cam.yaml:7: 'pose.translation' must be a list of 3 numbers, not a list of 2"},
      {eucm + "eucm: {alpha: 0.5, beta: 1, fu: 300, fv: 300, u0: 1, v0: 2}\n" +
           "pose:\n  translation: [1, 2, 3]\n  rotation: [0, 0, 1, 1]\n",
       "cam.yaml:8: 'pose.rotation' [qx, qy, qz, qw] has norm 1.41421, must be a unit quaternion"},
      {eucm + "eucm: {alpha: 0.5, beta: 1, fu: 300, fv: 300, u0: 1, v0: 2}\n" +
           "pose:\n  translation: [1, 2, 3]\n  rotation: [0, 0, x, 1]\n",
       "cam.yaml:8: 'pose.rotation' must be a number, not 'x'"},
      {eucm + "eucm: {alpha: 0.5, beta: 1, fu: 300, fv: 300, u0: 1, v0: 2}\n" +
           "pose:\n  translation: [1, 2, 3]\n",
       "cam.yaml:7: 'pose' needs 'rotation'"},
      {eucm + "eucm: {alpha: 0.5, beta: 1, fu: 300, fv: 300, u0: 1, v0: 2}\n" +
           "pose:\n  position: [1, 2, 3]\n",
       "cam.yaml:7: unknown key 'position' in 'pose' (keys: translation, rotation)"},
      {"camera_matrix: {rows: 3, cols: 3, data: [0, 0, 1, 0, 500, 1, 0, 0, 1]}\n",
       "cam.yaml:4: pinhole camera: focal lengths must be positive"},
      {"camera_matrix: {rows: 3, cols: 3, data: [500, 0, 1, 0, 500, 1, 0, 0]}\n",
       "cam.yaml:4: 'camera_matrix.data' must be a list of 9 numbers, not a list of 8"},
  };
  for (const Case& c : cases) {
    std::string message = error(c.rest);
    EXPECT_TRUE(message.starts_with(c.expected)) << message << "\nexpected: " << c.expected;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  EXPECT_THROW(parse_camera_file(head + cases[1].rest, "cam.yaml"), CameraFileError);
  std::string missing = error_of([] { load_camera_file("/nonexistent/cam.yaml"); });
  EXPECT_TRUE(missing.starts_with("/nonexistent/cam.yaml: cannot read: ")) << missing;
}

TEST(CameraFile, TheWriterRefusesWhatItCannotWrite) {
  CameraFile empty;
  EXPECT_THROW(format_camera_file(empty), std::invalid_argument);
  CameraFile camera;
  camera.model = std::make_shared<EucmCamera>(1024, 768, std::array<double, 6>{0.5, 1, 3, 3, 1, 1});
  std::string error = error_of([&] { save_camera_file("/nonexistent/dir/cam.yaml", camera); });
  EXPECT_TRUE(error.starts_with("/nonexistent/dir/cam.yaml: cannot write the camera file"))
      << error;
}

}  // namespace
}  // namespace mocap::calibration
