// Camera calibration as one least-squares problem on Ceres (seed 002 §2, §8): the intrinsics
// of every camera, the board's pose in every shot and the transforms between cameras, fitted
// to the board points the cameras saw by Levenberg–Marquardt.
//
//   CalibrationConfig config = load_calibration_config("calib_ir.json");
//   CalibrationProblem problem(config);          // throws CalibrationError for unusable input
//   CalibrationReport report = problem.solve();
//   std::cout << report.summary();
//
// Parameter blocks: each camera's intrinsics (EUCM: alpha, beta, fu, fv, u0, v0; pinhole: fx,
// fy, cx, cy, k1, k2, p1, p2, k3), each transform as [x, y, z, rx, ry, rz] (translation and
// rotation vector). A global transform is one block for the whole problem; a per-shot
// transform (the board's pose) one block per frame of its data file, shared by every camera
// that saw that frame, which ties the cameras together. Residuals: the pixel error of every
// board point, through the camera and the data entry's transform chain; and for a transform
// with a prior, its deviation from the prior times the stiffness.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <mocap/calibration/calibration_config.hpp>

namespace mocap::calibration {

// The configuration cannot be calibrated: too few shots, degenerate data, a value out of
// range. The message says which part and why.
class CalibrationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One iteration of the solve, as it goes: what a progress display shows.
struct SolveIteration {
  int iteration = 0;  // 0: the starting point
  // The RMS pixel error over every point the cost implies (exact where the robust loss leaves
  // a point's error as it is: below its scale).
  double rms_px = 0;
  // The cost's relative decrease in this iteration: Levenberg–Marquardt stops once it falls
  // under the function tolerance (1e-10), so its order of magnitude says how near the end is.
  double relative_decrease = 0;
};

struct CalibrationOptions {
  // Huber loss on each point's pixel error, with this scale (pixels): points further off
  // than it count linearly, so a few bad points cannot drag the fit. 0: plain least squares.
  double robust_scale_px = 0;
  int max_iterations = 500;
  // Shots whose RMS reprojection error exceeds this are flagged as outliers in the report.
  double outlier_rms_px = 3.0;
  // Standard deviations of the parameters from the covariance at the solution, when the solver
  // converged (a sparse QR factorization of the Jacobian: about as long as the solve).
  bool compute_covariance = true;
  // Called after each iteration of the solve, on the thread that solves; false ends the solve
  // there (it then reports not converged: "stopped").
  std::function<bool(const SolveIteration&)> on_iteration{};
};

struct CameraResult {
  std::string name;
  std::string type;
  std::vector<double> initial;
  std::vector<double> value;
  std::vector<double> standard_deviation;  // empty without covariance; 0 for constant values
  int shots = 0;
  double rms_px = 0;  // over all its points
};

struct TransformResult {
  std::string name;
  Eigen::Isometry3d value = Eigen::Isometry3d::Identity();
  // Of [x, y, z, rx, ry, rz] (metres, radians); empty without covariance.
  std::vector<double> standard_deviation;
};

struct ShotResult {
  size_t data = 0;   // index of the data entry
  size_t frame = 0;  // frame of its data file
  std::string camera;
  double rms_px = 0;
  bool outlier = false;
};

struct CalibrationReport {
  bool converged = false;
  std::string termination;  // why the solve stopped
  int iterations = 0;
  double initial_cost = 0, final_cost = 0;
  double initial_rms_px = 0, rms_px = 0;  // over every point
  size_t points = 0;
  std::vector<CameraResult> cameras;     // in the configuration's order
  std::vector<TransformResult> globals;  // the global transforms, in the configuration's order
  std::vector<ShotResult> shots;
  std::string covariance_problem;  // why the covariance could not be computed, if it could not

  size_t outliers() const;
  // A readable report: convergence, costs, cameras with standard deviations, global
  // transforms, per-shot RMS with the outliers marked.
  std::string summary() const;
};

class CalibrationProblem {
 public:
  // Builds the problem and its starting point: each per-shot transform from a planar PnP of
  // its first view through the initial camera (or the data entry's `init`). Throws
  // CalibrationError for a camera with too few shots to determine it (each shot of the
  // 4-point board adds 8 measurements and 6 unknowns, seed 002 §2.3), a shot whose points
  // are degenerate (collinear or coincident), or initial intrinsics the model rejects.
  explicit CalibrationProblem(const CalibrationConfig& config, CalibrationOptions options = {});
  ~CalibrationProblem();
  CalibrationProblem(const CalibrationProblem&) = delete;
  CalibrationProblem& operator=(const CalibrationProblem&) = delete;

  // Runs Levenberg–Marquardt and reports. The problem keeps the solution: the camera
  // poses below use it.
  CalibrationReport solve();

  // Where each camera is relative to `reference` (a camera name), from the global transforms
  // of the chains: camera_from_reference. Cameras the chains do not relate to the reference
  // (no shot seen by both) are missing. Throws CalibrationError for an unknown name.
  std::vector<std::pair<std::string, Eigen::Isometry3d>> camera_poses(
      const std::string& reference) const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace mocap::calibration
