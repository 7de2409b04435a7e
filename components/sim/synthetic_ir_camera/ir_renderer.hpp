// Renders a scene as an infrared camera sees it: retro-reflective markers as bright ellipses
// on a dark background, distractor lights, occluders and sensor noise; with the ground truth
// of every frame.
//
// Each marker is a flat disc of RenderOptions::marker_diameter_m in its board's plane, drawn
// exactly under the camera model: every pixel near the disc's image is covered by casting
// supersampling x supersampling rays through it (interpolated from RayTable), intersecting
// them with the board's plane and counting those that land inside the disc. Pixels whose
// corners all land inside (or whose footprint on the plane is far from the disc) skip the
// rays. A disc seen from behind (its board facing away) is not drawn. The coverage is blurred
// (Gaussian, on the marker's own patch), scaled by the exposure and added to the background;
// motion blur averages the coverage of several poses spread over the exposure time. Boards are
// opaque and dark: a board hides the markers of boards behind it (a marker whose centre is
// behind a nearer board, within its markers' rectangle grown by a centimetre, is not drawn).
//
// The random parts of a frame (the noise window, moving hot points) are a function of the
// scene's seed and the frame number only, so a frame renders the same every time.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

#include <mocap/calibration/camera_model.hpp>

#include "sim/synthetic_ir_camera/ray_table.hpp"
#include "sim/synthetic_ir_camera/scene.hpp"
#include "sim/synthetic_ir_camera/sensor_noise.hpp"

namespace mocap::synthetic {

struct MarkerTruth {
  // The projected centre of the marker (pixels), also when it faces away; NaN when the
  // camera cannot image it (behind the camera).
  Eigen::Vector2d pixel = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  // Facing the camera, its centre inside the image and not behind an occluder. A marker cut
  // by the image border or an occluder's edge counts as visible when its centre is.
  bool visible = false;
};

struct ObjectTruth {
  std::string constellation;
  // Constellation frame in the camera frame at mid-exposure (see trajectory.hpp).
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  bool in_front = false;       // its origin has z > 0
  bool facing_camera = false;  // the marker side of the board faces the camera
  // Velocity of the constellation frame in the camera frame at mid-exposure: of its origin
  // (m/s) and of its axes (rad/s, dR/dt = [angular]x R). The camera is held still.
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  std::vector<MarkerTruth> markers;  // in the order of the constellation's points

  int visible_markers() const;
};

struct RenderedFrame {
  cv::Mat image;                     // CV_8UC1, camera width x height
  double time_s = 0;                 // scene time at mid-exposure
  std::vector<ObjectTruth> objects;  // in the scene's order
};

// Not thread-safe: a renderer keeps its working buffers between frames.
class IrRenderer {
 public:
  // Precomputes what does not change between frames: the noise patterns, the static layer
  // (background, blobs, lamp, fixed occluders and hot points) and, per noise pattern, the
  // frame they make in 8 bits; the camera's rays follow as frames need them (ray_table.hpp).
  // A frame is then that background copied, and drawn in floating point only where something
  // moves or changes (markers, occluders, hot points): the same pixels as drawing the whole
  // frame in floating point, at a fraction of the cost (four 1280x720 cameras at 120 Hz on
  // two cores). Throws std::invalid_argument for a null camera or render options that cannot
  // be used (RenderOptions::problem; load_scene checks those of a file).
  IrRenderer(Scene scene, std::shared_ptr<const calibration::CameraModel> camera);

  // The frame whose exposure is centred on scene time `time_s`. `frame_number` selects the
  // frame's random draws. `camera_from_world` places the camera: the scene's trajectories are
  // in the world frame, which is the camera frame by default (a fixed camera). A moving camera
  // (on a turret, on a base) is held still over one exposure: motion blur comes from the
  // objects' motion only.
  RenderedFrame render(double time_s, uint64_t frame_number = 0,
                       const Eigen::Isometry3d& camera_from_world = Eigen::Isometry3d::Identity());

  const Scene& scene() const { return scene_; }
  const calibration::CameraModel& camera() const { return *camera_; }

 private:
  struct DiscView;  // one marker at one instant, as seen from the camera
  struct Rect {
    int x0 = 0, y0 = 0, x1 = -1, y1 = -1;  // inclusive pixel bounds
    bool empty() const { return x1 < x0 || y1 < y0; }
  };

  // The object's constellation frame in the camera frame at scene time `time_s`.
  Eigen::Isometry3d object_pose(const SceneObject& object, double time_s) const {
    return camera_from_world_ * pose_at(object.trajectory, time_s);
  }
  std::vector<double> exposure_times(const SceneObject& object, double time_s) const;
  bool view_disc(const Eigen::Isometry3d& pose, const Eigen::Vector3d& marker,
                 DiscView& view) const;
  void add_coverage(const DiscView& view, const Rect& patch_rect, double weight,
                    cv::Mat& patch) const;
  // Draws into work_.
  void draw_marker(const std::vector<Eigen::Isometry3d>& poses, const Eigen::Vector3d& marker);
  void draw_static_layer();
  cv::Rect area_of(const Rect& rect) const {
    return {rect.x0, rect.y0, rect.x1 - rect.x0 + 1, rect.y1 - rect.y0 + 1};
  }
  // Before drawing into `area` of work_: its pixels not drawn yet this frame get the static
  // layer plus the frame's noise.
  void begin_drawing(const cv::Rect& area);
  // `area` of work_ was written over whole this frame.
  void mark_drawn(const cv::Rect& area);
  void occlude(const Rect& rect, double level_dn, const cv::Mat& noise, cv::Mat& image) const;
  Rect object_occlusion(const SceneObject& object, const ObjectTruth& truth, double time_s) const;
  // Where `object` is at `time_s`, how fast it moves, and where its markers project.
  ObjectTruth object_truth(const SceneObject& object, double time_s) const;
  // The sensor's hot pixels, on top of everything in work_.
  void add_hot_points(std::mt19937_64& random);
  bool hidden_by_a_board(const Eigen::Vector3d& point, size_t own,
                         const std::vector<ObjectTruth>& objects) const;
  Rect clip(double x0, double y0, double x1, double y1) const;

  Scene scene_;
  std::shared_ptr<const calibration::CameraModel> camera_;
  Eigen::Isometry3d camera_from_world_ = Eigen::Isometry3d::Identity();  // of the current frame
  RayTable rays_;
  SensorNoise noise_;
  double marker_radius_m_;
  double peak_dn_;        // a fully covered pixel, above the background
  cv::Mat static_layer_;  // CV_32F: everything that does not move
  std::vector<Rect> fixed_occluders_;
  // Per object, the rectangle of its board in its own frame (metres).
  struct BoardExtent {
    double x0 = std::numeric_limits<double>::infinity(), y0 = x0;
    double x1 = -std::numeric_limits<double>::infinity(), y1 = x1;
  };
  std::vector<BoardExtent> board_extents_;
  std::vector<cv::Point> fixed_hot_points_;
  std::vector<cv::Mat> backgrounds_;   // CV_8U: static_layer_ plus each noise pattern, rounded
  cv::Mat noise_pattern_;              // CV_32F view: the current frame's noise; empty: none
  cv::Mat work_;                       // CV_32F: the frame being drawn, where drawn_ says
  cv::Mat drawn_;                      // CV_8U: 1 where work_ holds the current frame
  std::vector<cv::Rect> drawn_areas_;  // where drawn_ is 1
  cv::Mat patch_;                      // CV_32F: one marker's coverage
};

}  // namespace mocap::synthetic
