#include <mocap/calibration/calibration_problem.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <numeric>
#include <optional>
#include <set>

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <fmt/format.h>
#include <Eigen/Eigenvalues>
#include <mocap/calibration/camera_factory.hpp>
#include <mocap/calibration/lens_models.hpp>
#include <opencv2/calib3d.hpp>

namespace mocap::calibration {
namespace {

using Pose6 = std::array<double, 6>;  // x, y, z, rx, ry, rz

Pose6 to_pose6(const Eigen::Isometry3d& transform) {
  const std::vector<double> values = transform_to_values6(transform);
  Pose6 pose;
  std::copy(values.begin(), values.end(), pose.begin());
  return pose;
}

Eigen::Isometry3d to_isometry(const Pose6& pose) { return transform_from_values(pose); }

// `point` moved by a transform block: direct, p' = R p + t; inverse, p' = Rᵀ (p − t).
template <class T>
void transform_point(const T* pose, bool direct, T* point) {
  T moved[3];
  if (direct) {
    ceres::AngleAxisRotatePoint(pose + 3, point, moved);
    for (int i = 0; i < 3; ++i) point[i] = moved[i] + pose[i];
  } else {
    const T shifted[3] = {point[0] - pose[0], point[1] - pose[1], point[2] - pose[2]};
    const T back[3] = {-pose[3], -pose[4], -pose[5]};
    ceres::AngleAxisRotatePoint(back, shifted, moved);
    for (int i = 0; i < 3; ++i) point[i] = moved[i];
  }
}

enum class Lens { kPinhole, kEucm, kUcm, kMei };

// The configuration reader has checked that `type` is one of these.
Lens lens_of(const std::string& type) {
  if (type == "eucm") return Lens::kEucm;
  if (type == "ucm") return Lens::kUcm;
  if (type == "mei") return Lens::kMei;
  return Lens::kPinhole;
}

// The pixel error of one board point: parameter block 0 is the camera, then one block per
// link of the chain, left to right (T = T1 T2 ... Tn: Tn is applied first).
struct PointResidual {
  Lens lens = Lens::kPinhole;
  Eigen::Vector3d object;
  Eigen::Vector2d observed;
  std::vector<bool> direct;

  template <class T>
  bool operator()(T const* const* parameters, T* residuals) const {
    T point[3] = {T(object.x()), T(object.y()), T(object.z())};
    for (size_t i = direct.size(); i-- > 0;) transform_point(parameters[1 + i], direct[i], point);
    T pixel[2];
    if (!project(parameters[0], point, pixel)) return false;
    residuals[0] = pixel[0] - T(observed.x());
    residuals[1] = pixel[1] - T(observed.y());
    return true;
  }

  template <class T>
  bool project(const T* camera, const T* point, T* pixel) const {
    switch (lens) {
      case Lens::kEucm:
        return eucm_project(camera, point, pixel);
      case Lens::kUcm:
        return ucm_project(camera, point, pixel);
      case Lens::kMei:
        return mei_project(camera, point, pixel);
      case Lens::kPinhole:
        break;
    }
    return pinhole_project(camera, point, pixel);
  }
};

// A transform's deviation from its prior, weighted: [t − t0; rotation vector of R0ᵀ R].
struct PriorResidual {
  Eigen::Isometry3d prior;
  double stiffness = 1;

  template <class T>
  bool operator()(const T* pose, T* residuals) const {
    for (int i = 0; i < 3; ++i) residuals[i] = T(stiffness) * (pose[i] - T(prior.translation()[i]));
    T rotation[9];
    ceres::AngleAxisToRotationMatrix(pose + 3, ceres::RowMajorAdapter3x3(rotation));
    T relative[9];
    const Eigen::Matrix3d& r0 = prior.linear();
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        relative[3 * i + j] = T(r0(0, i)) * rotation[j] + T(r0(1, i)) * rotation[3 + j] +
                              T(r0(2, i)) * rotation[6 + j];
      }
    }
    ceres::RotationMatrixToAngleAxis(ceres::RowMajorAdapter3x3<const T>(relative), residuals + 3);
    for (int i = 3; i < 6; ++i) residuals[i] *= T(stiffness);
    return true;
  }
};

int free_intrinsics(const CameraSpec& camera) {
  return camera.constant ? 0 : static_cast<int>(camera.value.size());
}

// Whether the points span an area: not all on one line or in one spot (half a pixel).
bool spans_an_area(const std::vector<Eigen::Vector2d>& points) {
  if (points.size() < 3) return false;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const auto& p : points) scatter += (p - mean) * (p - mean).transpose();
  scatter /= static_cast<double>(points.size());
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(scatter).eigenvalues().minCoeff() > 0.25;
}

// "images" entries get their shots and image size from the images (find_board_shots in
// mocap_calibrate): without them nothing would say what went wrong.
void check_image_sizes(const CalibrationConfig& config) {
  for (size_t d = 0; d < config.data.size(); ++d) {
    const DataSpec& data = config.data[d];
    if (data.image_width <= 0 || data.image_height <= 0) {
      throw CalibrationError(fmt::format(
          "{}: data[{}] ({}): no image size{}", config.source, d, data.camera,
          data.type == "images" ? ": the board has not been looked for in its images" : ""));
    }
  }
}

// Enough data for each camera: each shot of n points adds 2n measurements and 6 unknowns.
void check_enough_shots(const CalibrationConfig& config) {
  for (const CameraSpec& camera : config.cameras) {
    int shots = 0, net = 0, points = 4;
    for (const DataSpec& data : config.data) {
      if (data.camera != camera.name) continue;
      for (const Shot& shot : data.shots) {
        ++shots;
        points = static_cast<int>(shot.points.size());
        net += 2 * points - 6;
      }
    }
    const int unknowns = free_intrinsics(camera);
    if (unknowns > 0 && net <= unknowns) {
      const int needed = unknowns / std::max(1, 2 * points - 6) + 1;
      throw CalibrationError(fmt::format(
          "{}: camera {}: {} shots are too few for its {} intrinsics: each shot of {} points "
          "adds {} measurements and 6 unknowns (its board pose), so {} shots are needed at least "
          "(seed 002 §2.3); more, from different angles, make the result reliable",
          config.source, camera.name, shots, unknowns, points, 2 * points, needed));
    }
  }
}

// The board's pose in the camera for one shot, from a planar PnP through the initial lens
// model `model`. `where` names the shot in errors.
Eigen::Isometry3d initial_board_pose(const CameraModel& model,
                                     const std::vector<cv::Point3d>& object, const Shot& shot,
                                     const std::string& where) {
  std::vector<cv::Point2d> normalised;
  for (const Eigen::Vector2d& pixel : shot.points) {
    auto ray = model.unproject(pixel);
    if (!ray) throw CalibrationError(where + ": a point is outside the initial lens model");
    normalised.emplace_back(ray->x(), ray->y());
  }
  const bool planar = std::all_of(object.begin(), object.end(),
                                  [&](const cv::Point3d& p) { return p.z == object[0].z; });
  // A planar target has two poses that fit about equally (IPPE gives both); of those
  // with the whole board in front of the camera, the one that fits best.
  std::vector<cv::Mat> rvecs, tvecs;
  std::vector<double> errors;
  cv::solvePnPGeneric(object, normalised, cv::Mat::eye(3, 3, CV_64F), cv::Mat(), rvecs, tvecs,
                      false, planar ? cv::SOLVEPNP_IPPE : cv::SOLVEPNP_ITERATIVE, cv::noArray(),
                      cv::noArray(), errors);
  std::optional<Eigen::Isometry3d> best;
  double best_error = 0;
  for (size_t k = 0; k < rvecs.size(); ++k) {
    const Pose6 pose = {tvecs[k].at<double>(0), tvecs[k].at<double>(1), tvecs[k].at<double>(2),
                        rvecs[k].at<double>(0), rvecs[k].at<double>(1), rvecs[k].at<double>(2)};
    const Eigen::Isometry3d candidate = to_isometry(pose);
    const bool in_front = std::all_of(object.begin(), object.end(), [&](const cv::Point3d& p) {
      return (candidate * Eigen::Vector3d(p.x, p.y, p.z)).z() > 0;
    });
    const double error = k < errors.size() ? errors[k] : 0.0;
    if (in_front && (!best || error < best_error)) {
      best = candidate;
      best_error = error;
    }
  }
  if (!best) {
    throw CalibrationError(where +
                           ": no board pose in front of the camera fits the points (are "
                           "they the board's points, in the order of its corners?)");
  }
  return *best;
}

// Bounds that keep each lens model's parameters physical.
void bound_intrinsics(ceres::Problem& problem, double* block, const CameraSpec& spec) {
  if (spec.type == "eucm") {
    problem.SetParameterLowerBound(block, 0, 0.0);  // alpha in [0, 1]
    problem.SetParameterUpperBound(block, 0, 1.0);
    // beta > 0, and not beyond 100: in a narrow view only alpha and beta's combined bending
    // shows, and without a ceiling the fit creeps along that valley for hundreds of
    // iterations towards alpha = 0, beta -> infinity, changing nothing that can be seen.
    problem.SetParameterLowerBound(block, 1, 1e-6);
    problem.SetParameterUpperBound(block, 1, 100.0);
    problem.SetParameterLowerBound(block, 2, 1.0);  // focal lengths
    problem.SetParameterLowerBound(block, 3, 1.0);
  } else if (spec.type == "ucm" || spec.type == "mei") {
    problem.SetParameterLowerBound(block, 0, 0.0);  // xi
    const int fu = static_cast<int>(spec.value.size()) - 4;
    problem.SetParameterLowerBound(block, fu, 1.0);
    problem.SetParameterLowerBound(block, fu + 1, 1.0);
  } else {
    problem.SetParameterLowerBound(block, 0, 1.0);
    problem.SetParameterLowerBound(block, 1, 1.0);
    if (spec.value.size() == 4) {
      problem.SetManifold(block, new ceres::SubsetManifold(kPinholeParameters, {4, 5, 6, 7, 8}));
    }
  }
}

// Ceres's iterations as SolveIteration. The cost is half the sum of squared pixel errors, two
// per point.
class IterationReporter final : public ceres::IterationCallback {
 public:
  IterationReporter(std::function<bool(const SolveIteration&)> report, size_t points)
      : report_(std::move(report)), points_(std::max<size_t>(points, 1)) {}

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    const double before = summary.cost + summary.cost_change;
    const bool go_on =
        report_({.iteration = summary.iteration,
                 .rms_px = std::sqrt(2 * summary.cost / static_cast<double>(points_)),
                 .relative_decrease = before > 0 ? summary.cost_change / before : 0});
    return go_on ? ceres::SOLVER_CONTINUE : ceres::SOLVER_ABORT;
  }

 private:
  std::function<bool(const SolveIteration&)> report_;
  size_t points_;
};

}  // namespace

struct CalibrationProblem::State {
  CalibrationConfig config;
  CalibrationOptions options;
  ceres::Problem problem;
  std::vector<std::vector<double>> cameras;  // per CameraSpec
  std::vector<Pose6> transforms;             // per TransformSpec (globals; per-shot unused)
  // Per-shot transforms: (transform index, data file, frame) -> pose.
  std::map<std::tuple<size_t, std::string, size_t>, Pose6> shot_poses;
  struct ShotResiduals {
    size_t data, shot;
    std::vector<ceres::ResidualBlockId> points;
  };
  std::vector<ShotResiduals> shot_residuals;
  std::map<std::string, size_t> camera_index, transform_index;

  // The chain's per-shot link.
  size_t shot_link(const DataSpec& data) const {
    for (size_t i = 0; i < data.transform_chain.size(); ++i) {
      if (!config.transformations[transform_index.at(data.transform_chain[i].name)].global) {
        return i;
      }
    }
    return 0;  // the configuration reader guarantees one
  }
  Eigen::Isometry3d link_value(const ChainLink& link) const {
    const Eigen::Isometry3d value = to_isometry(transforms[transform_index.at(link.name)]);
    return link.direct ? value : value.inverse();
  }
  double* pose_block(const DataSpec& data, size_t link, size_t frame) {
    const size_t t = transform_index.at(data.transform_chain[link].name);
    if (config.transformations[t].global) return transforms[t].data();
    return shot_poses.at({t, data.data_path, frame}).data();
  }
  // The squared pixel errors of a shot's points, summed.
  double squared_error(const ShotResiduals& shot) {
    double sum = 0;
    for (ceres::ResidualBlockId id : shot.points) {
      double residuals[2], cost = 0;
      problem.EvaluateResidualBlock(id, false, &cost, residuals, nullptr);
      sum += residuals[0] * residuals[0] + residuals[1] * residuals[1];
    }
    return sum;
  }
  // Residuals (point coordinates and priors) less the free parameters' degrees of freedom.
  double degrees_of_freedom() const {
    std::vector<double*> blocks;
    problem.GetParameterBlocks(&blocks);
    int free = 0;
    for (double* block : blocks) {
      if (!problem.IsParameterBlockConstant(block))
        free += problem.ParameterBlockTangentSize(block);
    }
    return static_cast<double>(problem.NumResiduals() - free);
  }
  // Over every point, pixels.
  double rms() {
    double sum = 0;
    size_t count = 0;
    for (const ShotResiduals& shot : shot_residuals) {
      sum += squared_error(shot);
      count += shot.points.size();
    }
    return count > 0 ? std::sqrt(sum / static_cast<double>(count)) : 0.0;
  }

  // Starting values of the per-shot transforms of data entry `d`: a planar PnP of the first
  // view of each frame through the initial camera, moved through the chain's other (global)
  // links.
  void initialize_shot_poses(size_t d) {
    const DataSpec& data = config.data[d];
    const size_t c = camera_index.at(data.camera);
    const CameraSpec& spec = config.cameras[c];
    std::shared_ptr<const CameraModel> model;
    try {
      model = make_camera_model(spec.type, data.image_width, data.image_height, cameras[c]);
    } catch (const std::invalid_argument& e) {
      throw CalibrationError(fmt::format("{}: camera {}: {}", config.source, spec.name, e.what()));
    }
    const size_t link = shot_link(data);
    const size_t t = transform_index.at(data.transform_chain[link].name);
    Eigen::Isometry3d prefix = Eigen::Isometry3d::Identity(), suffix = prefix;
    for (size_t i = 0; i < link; ++i) prefix = prefix * link_value(data.transform_chain[i]);
    for (size_t i = link + 1; i < data.transform_chain.size(); ++i) {
      suffix = suffix * link_value(data.transform_chain[i]);
    }
    std::vector<cv::Point3d> object;
    for (int corner : data.corners) {
      const Eigen::Vector3d& p = data.object_points[static_cast<size_t>(corner)];
      object.emplace_back(p.x(), p.y(), p.z());
    }
    for (const Shot& shot : data.shots) {
      const auto key = std::make_tuple(t, data.data_path, shot.frame);
      if (shot_poses.count(key)) continue;
      const std::string where = fmt::format("{}: data[{}] ({}), frame {} of {}", config.source, d,
                                            data.camera, shot.frame, data.data_file);
      if (!spans_an_area(shot.points)) {
        throw CalibrationError(where + ": the points are (nearly) on one line or in one spot");
      }
      const Eigen::Isometry3d camera_from_board =
          data.init ? *data.init : initial_board_pose(*model, object, shot, where);
      Eigen::Isometry3d shot_pose = prefix.inverse() * camera_from_board * suffix.inverse();
      if (!data.transform_chain[link].direct) shot_pose = shot_pose.inverse();
      shot_poses[key] = to_pose6(shot_pose);
    }
  }

  // One residual block per observed point: its pixel error through the entry's chain.
  void add_point_residuals() {
    ceres::LossFunction* loss = nullptr;  // the problem owns it (one instance, shared)
    if (options.robust_scale_px > 0) loss = new ceres::HuberLoss(options.robust_scale_px);
    for (size_t d = 0; d < config.data.size(); ++d) {
      const DataSpec& data = config.data[d];
      const size_t c = camera_index.at(data.camera);
      std::vector<bool> direct;
      for (const ChainLink& link : data.transform_chain) direct.push_back(link.direct);
      for (size_t k = 0; k < data.shots.size(); ++k) {
        const Shot& shot = data.shots[k];
        ShotResiduals residuals{d, k, {}};
        std::vector<double*> blocks = {cameras[c].data()};
        for (size_t i = 0; i < data.transform_chain.size(); ++i) {
          blocks.push_back(pose_block(data, i, shot.frame));
        }
        for (size_t p = 0; p < shot.points.size(); ++p) {
          auto* cost = new ceres::DynamicAutoDiffCostFunction<PointResidual, 4>(new PointResidual{
              lens_of(config.cameras[c].type),
              data.object_points[static_cast<size_t>(data.corners[p])], shot.points[p], direct});
          cost->AddParameterBlock(static_cast<int>(cameras[c].size()));
          for (size_t i = 0; i < data.transform_chain.size(); ++i) cost->AddParameterBlock(6);
          cost->SetNumResiduals(2);
          residuals.points.push_back(problem.AddResidualBlock(cost, loss, blocks));
        }
        shot_residuals.push_back(std::move(residuals));
      }
    }
  }

  // Priors, constants, bounds.
  void add_priors_and_bounds() {
    for (size_t t = 0; t < config.transformations.size(); ++t) {
      const TransformSpec& spec = config.transformations[t];
      if (!spec.global || !problem.HasParameterBlock(transforms[t].data())) continue;
      if (spec.constant) problem.SetParameterBlockConstant(transforms[t].data());
      if (spec.prior && !spec.constant) {
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<PriorResidual, 6, 6>(new PriorResidual{
                spec.value.value_or(Eigen::Isometry3d::Identity()), spec.prior_stiffness}),
            nullptr, transforms[t].data());
      }
    }
    for (size_t c = 0; c < config.cameras.size(); ++c) {
      double* block = cameras[c].data();
      if (!problem.HasParameterBlock(block)) continue;
      if (config.cameras[c].constant) {
        problem.SetParameterBlockConstant(block);
      } else {
        bound_intrinsics(problem, block, config.cameras[c]);
      }
    }
  }

  // Standard deviations of the free cameras' and global transforms' values, scaled by the
  // residuals' own spread (the pixel noise is not given); or why there are none.
  struct Deviations {
    std::vector<std::vector<double>> cameras;     // per CameraSpec; empty: none
    std::vector<std::vector<double>> transforms;  // per TransformSpec; empty: none
    std::string problem;
  };
  Deviations standard_deviations(double final_cost) {
    Deviations result{std::vector<std::vector<double>>(cameras.size()),
                      std::vector<std::vector<double>>(transforms.size()),
                      {}};
    std::vector<const double*> blocks;
    for (auto& camera : cameras) {
      if (problem.HasParameterBlock(camera.data()) &&
          !problem.IsParameterBlockConstant(camera.data())) {
        blocks.push_back(camera.data());
      }
    }
    for (size_t t = 0; t < transforms.size(); ++t) {
      if (config.transformations[t].global && problem.HasParameterBlock(transforms[t].data()) &&
          !problem.IsParameterBlockConstant(transforms[t].data())) {
        blocks.push_back(transforms[t].data());
      }
    }
    if (blocks.empty()) return result;  // nothing free: nothing to report
    std::vector<std::pair<const double*, const double*>> pairs;
    for (const double* block : blocks) pairs.emplace_back(block, block);
    ceres::Covariance::Options covariance_options;
    // Sparse: a rig has thousands of per-shot pose values (a dense SVD of them took a minute).
    // A rank-deficient Jacobian makes Compute fail, reported below, rather than guess.
    covariance_options.algorithm_type = ceres::SPARSE_QR;
    ceres::Covariance covariance(covariance_options);
    if (!covariance.Compute(pairs, &problem)) {
      result.problem =
          "the parameters are not all determined by the data (rank-deficient): more shots, "
          "from more different angles, are needed";
      return result;
    }
    const double dof = degrees_of_freedom();
    const double variance = dof > 0 ? 2 * final_cost / dof : 1.0;
    auto sigmas = [&](const double* block, int size) {
      std::vector<double> values(static_cast<size_t>(size));
      std::vector<double> matrix(static_cast<size_t>(size * size));
      covariance.GetCovarianceBlock(block, block, matrix.data());
      for (int i = 0; i < size; ++i) {
        values[static_cast<size_t>(i)] =
            std::sqrt(std::max(0.0, matrix[static_cast<size_t>(i * size + i)] * variance));
      }
      return values;
    };
    for (size_t c = 0; c < cameras.size(); ++c) {
      if (std::find(blocks.begin(), blocks.end(), cameras[c].data()) != blocks.end()) {
        result.cameras[c] = sigmas(cameras[c].data(), static_cast<int>(cameras[c].size()));
      }
    }
    for (size_t t = 0; t < transforms.size(); ++t) {
      if (std::find(blocks.begin(), blocks.end(), transforms[t].data()) != blocks.end()) {
        result.transforms[t] = sigmas(transforms[t].data(), 6);
      }
    }
    return result;
  }
};

CalibrationProblem::CalibrationProblem(const CalibrationConfig& config, CalibrationOptions options)
    : state_(std::make_unique<State>()) {
  check_image_sizes(config);
  check_enough_shots(config);
  State& s = *state_;
  s.config = config;
  s.options = options;
  for (size_t i = 0; i < config.cameras.size(); ++i) s.camera_index[config.cameras[i].name] = i;
  for (size_t i = 0; i < config.transformations.size(); ++i) {
    s.transform_index[config.transformations[i].name] = i;
    s.transforms.push_back(
        to_pose6(config.transformations[i].value.value_or(Eigen::Isometry3d::Identity())));
  }
  // Intrinsics: pinhole with 4 values is solved without distortion (held at 0).
  for (const CameraSpec& camera : config.cameras) {
    std::vector<double> value = camera.value;
    if (camera.type == "pinhole" && value.size() == 4) value.resize(kPinholeParameters, 0.0);
    s.cameras.push_back(std::move(value));
  }
  for (size_t d = 0; d < config.data.size(); ++d) s.initialize_shot_poses(d);
  s.add_point_residuals();
  if (s.shot_residuals.empty()) {
    throw CalibrationError(config.source + ": no shots: the data files hold no usable frames");
  }
  s.add_priors_and_bounds();
}

CalibrationProblem::~CalibrationProblem() = default;

CalibrationReport CalibrationProblem::solve() {
  State& s = *state_;
  CalibrationReport report;
  report.initial_rms_px = s.rms();

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_SCHUR;
  options.max_num_iterations = s.options.max_iterations;
  // Tighter than Ceres's defaults: lens parameters lie along shallow valleys (EUCM's alpha and
  // beta act almost only through their product in a narrow view), where the defaults stop early.
  options.function_tolerance = 1e-10;
  options.gradient_tolerance = 1e-12;
  options.parameter_tolerance = 1e-10;
  size_t points = 0;
  for (const State::ShotResiduals& shot : s.shot_residuals) points += shot.points.size();
  IterationReporter reporter(s.options.on_iteration, points);
  if (s.options.on_iteration) options.callbacks.push_back(&reporter);
  ceres::Solver::Summary summary;
  ceres::Solve(options, &s.problem, &summary);
  report.converged = summary.termination_type == ceres::CONVERGENCE;
  report.termination = summary.message;
  report.iterations = static_cast<int>(summary.iterations.size()) - 1;
  report.initial_cost = summary.initial_cost;
  report.final_cost = summary.final_cost;
  report.points = 0;

  // Per shot and per camera.
  std::vector<double> camera_sum(s.config.cameras.size(), 0.0);
  std::vector<size_t> camera_points(s.config.cameras.size(), 0), camera_shots(camera_sum.size());
  double total = 0;
  for (const State::ShotResiduals& shot : s.shot_residuals) {
    const DataSpec& data = s.config.data[shot.data];
    const size_t c = s.camera_index.at(data.camera);
    const double sum = s.squared_error(shot);
    total += sum;
    camera_sum[c] += sum;
    camera_points[c] += shot.points.size();
    ++camera_shots[c];
    report.points += shot.points.size();
    const double rms = std::sqrt(sum / static_cast<double>(shot.points.size()));
    report.shots.push_back(
        {shot.data, data.shots[shot.shot].frame, data.camera, rms, rms > s.options.outlier_rms_px});
  }
  report.rms_px = std::sqrt(total / static_cast<double>(report.points));

  // Only at a solution: after a failed solve the Jacobian may not even be finite.
  State::Deviations deviations;
  if (s.options.compute_covariance && report.converged) {
    deviations = s.standard_deviations(summary.final_cost);
    report.covariance_problem = deviations.problem;
  }
  std::vector<std::vector<double>>& camera_sigma = deviations.cameras;
  std::vector<std::vector<double>>& transform_sigma = deviations.transforms;
  camera_sigma.resize(s.config.cameras.size());
  transform_sigma.resize(s.config.transformations.size());

  for (size_t c = 0; c < s.config.cameras.size(); ++c) {
    const CameraSpec& spec = s.config.cameras[c];
    CameraResult result;
    result.name = spec.name;
    result.type = spec.type;
    result.initial = spec.value;
    result.value = s.cameras[c];
    if (spec.type == "pinhole" && spec.value.size() == 4) result.value.resize(4);
    result.standard_deviation = camera_sigma[c];
    if (!result.standard_deviation.empty()) {
      result.standard_deviation.resize(result.value.size());
    }
    result.shots = static_cast<int>(camera_shots[c]);
    result.rms_px = camera_points[c] > 0
                        ? std::sqrt(camera_sum[c] / static_cast<double>(camera_points[c]))
                        : 0.0;
    report.cameras.push_back(std::move(result));
  }
  for (size_t t = 0; t < s.config.transformations.size(); ++t) {
    if (!s.config.transformations[t].global) continue;
    report.globals.push_back(
        {s.config.transformations[t].name, to_isometry(s.transforms[t]), transform_sigma[t]});
  }
  return report;
}

std::vector<std::pair<std::string, Eigen::Isometry3d>> CalibrationProblem::camera_poses(
    const std::string& reference) const {
  const State& s = *state_;
  if (!s.camera_index.count(reference)) {
    throw CalibrationError(fmt::format("{}: no camera named '{}'", s.config.source, reference));
  }
  // camera_from_shot_frame per (camera, data file): the chain's links before the per-shot one.
  struct View {
    std::string camera, data_path;
    Eigen::Isometry3d camera_from_shot;
  };
  std::vector<View> views;
  for (const DataSpec& data : s.config.data) {
    Eigen::Isometry3d prefix = Eigen::Isometry3d::Identity();
    for (size_t i = 0; i < s.shot_link(data); ++i)
      prefix = prefix * s.link_value(data.transform_chain[i]);
    views.push_back({data.camera, data.data_path, prefix});
  }
  std::vector<std::pair<std::string, Eigen::Isometry3d>> poses;
  for (const CameraSpec& camera : s.config.cameras) {
    std::optional<Eigen::Isometry3d> pose;
    for (const View& mine : views) {
      if (mine.camera != camera.name || pose) continue;
      for (const View& theirs : views) {
        if (theirs.camera == reference && theirs.data_path == mine.data_path) {
          pose = mine.camera_from_shot * theirs.camera_from_shot.inverse();
          break;
        }
      }
    }
    if (camera.name == reference) pose = Eigen::Isometry3d::Identity();
    if (pose) poses.emplace_back(camera.name, *pose);
  }
  return poses;
}

size_t CalibrationReport::outliers() const {
  return static_cast<size_t>(
      std::count_if(shots.begin(), shots.end(), [](const ShotResult& s) { return s.outlier; }));
}

std::string CalibrationReport::summary() const {
  std::string text = fmt::format(
      "{} after {} iterations: {}\ncost {:.6g} -> {:.6g}; RMS reprojection error {:.4f} -> {:.4f} "
      "px over {} points\n",
      converged ? "converged" : "NOT converged", iterations, termination, initial_cost, final_cost,
      initial_rms_px, rms_px, points);
  for (const CameraResult& camera : cameras) {
    text += fmt::format("camera {} ({}): {} shots, RMS {:.4f} px\n", camera.name, camera.type,
                        camera.shots, camera.rms_px);
    for (size_t i = 0; i < camera.value.size(); ++i) {
      text += fmt::format("  [{}] {:.6g} (from {:.6g})", i, camera.value[i],
                          i < camera.initial.size() ? camera.initial[i] : 0.0);
      if (i < camera.standard_deviation.size()) {
        text += fmt::format(" ± {:.3g}", camera.standard_deviation[i]);
      }
      text += "\n";
    }
  }
  for (const TransformResult& transform : globals) {
    const std::vector<double> v = transform_to_values6(transform.value);
    text += fmt::format(
        "transform {}: x y z {:.5f} {:.5f} {:.5f} m, rotation vector {:.5f} "
        "{:.5f} {:.5f} rad\n",
        transform.name, v[0], v[1], v[2], v[3], v[4], v[5]);
    if (transform.standard_deviation.size() == 6) {
      const auto& d = transform.standard_deviation;
      text += fmt::format("  ± {:.2g} {:.2g} {:.2g} m, ± {:.2g} {:.2g} {:.2g} rad\n", d[0], d[1],
                          d[2], d[3], d[4], d[5]);
    }
  }
  if (!covariance_problem.empty()) text += "no standard deviations: " + covariance_problem + "\n";
  text += fmt::format("{} shots, {} outliers", shots.size(), outliers());
  for (const ShotResult& shot : shots) {
    if (shot.outlier) {
      text += fmt::format("\n  outlier: data[{}] frame {} ({}): RMS {:.3f} px", shot.data,
                          shot.frame, shot.camera, shot.rms_px);
    }
  }
  return text + "\n";
}

}  // namespace mocap::calibration
