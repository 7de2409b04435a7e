#include "sim/synthetic_ir_camera/ir_renderer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace mocap::synthetic {
namespace {

// Markers closer than this (metres) are not drawn: they would fill the image.
constexpr double kNearestMarker_m = 0.01;
// Points on a disc's rim projected to bound its image; the bound is widened by a pixel to
// cover the rim between them.
constexpr int kRimSamples = 16;
// Motion blur poses are spaced so that no marker moves more than this between two (pixels).
constexpr double kMotionBlurStep_px = 0.25;
constexpr int kMaxMotionBlurSteps = 64;

uint64_t splitmix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// The fraction of `samples` x `samples` points spread over pixel (u, v) for which `inside`
// holds: the anti-aliased coverage of a 2D shape.
template <class Inside>
double pixel_coverage(int u, int v, int samples, Inside inside) {
  int count = 0;
  for (int j = 0; j < samples; ++j) {
    for (int i = 0; i < samples; ++i) {
      if (inside(u - 0.5 + (i + 0.5) / samples, v - 0.5 + (j + 0.5) / samples)) ++count;
    }
  }
  return static_cast<double>(count) / (samples * samples);
}

// The scene, once its render options are known to be usable: the members built from them (the
// noise, the markers' radius) need it.
Scene checked(Scene scene) {
  if (auto problem = scene.render.problem()) {
    throw std::invalid_argument("RenderOptions::" + *problem);
  }
  return scene;
}

}  // namespace

int ObjectTruth::visible_markers() const {
  return static_cast<int>(std::count_if(markers.begin(), markers.end(),
                                        [](const MarkerTruth& marker) { return marker.visible; }));
}

struct IrRenderer::DiscView {
  Eigen::Vector3d centre;   // camera frame
  Eigen::Vector3d normal;   // out of the marker side
  double plane_offset = 0;  // normal . centre: negative when the disc faces the camera
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // bounds of its image, pixels
};

IrRenderer::IrRenderer(Scene scene, std::shared_ptr<const calibration::CameraModel> camera)
    : scene_(checked(std::move(scene))),
      camera_(camera ? std::move(camera)
                     : throw std::invalid_argument("IrRenderer: no camera model")),
      rays_(camera_),
      noise_(camera_->width(), camera_->height(), scene_.render.noise_sigma_dn, scene_.seed),
      marker_radius_m_(0.5 * scene_.render.marker_diameter_m),
      peak_dn_(255.0 * scene_.render.exposure) {
  draw_static_layer();
  for (int pattern = 0; pattern < noise_.patterns(); ++pattern) {
    cv::Mat sum;
    if (noise_.enabled()) {
      cv::add(static_layer_, noise_.pattern(pattern), sum);
    } else {
      sum = static_layer_;
    }
    sum.convertTo(backgrounds_.emplace_back(), CV_8U);  // rounds and saturates to 0..255
  }
  work_.create(static_layer_.size(), CV_32F);
  drawn_ = cv::Mat::zeros(static_layer_.size(), CV_8U);
  // A board reaches a marker's radius and a centimetre beyond its outermost markers.
  for (const SceneObject& object : scene_.objects) {
    BoardExtent extent;
    for (const Eigen::Vector3d& marker : object.markers) {
      extent.x0 = std::min(extent.x0, marker.x());
      extent.y0 = std::min(extent.y0, marker.y());
      extent.x1 = std::max(extent.x1, marker.x());
      extent.y1 = std::max(extent.y1, marker.y());
    }
    const double border = marker_radius_m_ + 0.01;
    extent.x0 -= border;
    extent.y0 -= border;
    extent.x1 += border;
    extent.y1 += border;
    board_extents_.push_back(extent);
  }
}

IrRenderer::Rect IrRenderer::clip(double x0, double y0, double x1, double y1) const {
  // Pixel u spans [u - 0.5, u + 0.5]; clamp before converting so huge bounds cannot overflow.
  auto first = [](double low, int size) {
    return static_cast<int>(std::clamp(std::floor(low + 0.5), 0.0, static_cast<double>(size)));
  };
  auto last = [](double high, int size) {
    return static_cast<int>(std::clamp(std::floor(high + 0.5), -1.0, size - 1.0));
  };
  return {first(x0, camera_->width()), first(y0, camera_->height()), last(x1, camera_->width()),
          last(y1, camera_->height())};
}

void IrRenderer::draw_static_layer() {
  const RenderOptions& options = scene_.render;
  const Distractors& distractors = scene_.distractors;
  static_layer_.create(camera_->height(), camera_->width(), CV_32F);
  static_layer_.setTo(options.background_dn);

  if (const std::optional<Lamp>& lamp = distractors.lamp) {
    double reach = lamp->radius_px + 4 * lamp->glow_px;
    Rect area = clip(lamp->centre_px.x() - reach, lamp->centre_px.y() - reach,
                     lamp->centre_px.x() + reach, lamp->centre_px.y() + reach);
    for (int v = area.y0; v <= area.y1; ++v) {
      for (int u = area.x0; u <= area.x1; ++u) {
        // Averaging the profile over the pixel keeps the disc's edge smooth without a glow.
        double sum = 0;
        constexpr int kSamples = 4;
        for (int j = 0; j < kSamples; ++j) {
          for (int i = 0; i < kSamples; ++i) {
            double r = std::hypot(u - 0.5 + (i + 0.5) / kSamples - lamp->centre_px.x(),
                                  v - 0.5 + (j + 0.5) / kSamples - lamp->centre_px.y());
            double beyond = (r - lamp->radius_px) / std::max(lamp->glow_px, 1e-9);
            sum += r <= lamp->radius_px ? 1.0
                   : lamp->glow_px > 0  ? std::exp(-0.5 * beyond * beyond)
                                        : 0.0;
          }
        }
        static_layer_.at<float>(v, u) +=
            static_cast<float>(lamp->brightness_dn * sum / (kSamples * kSamples));
      }
    }
  }

  for (const Blob& blob : distractors.blobs) {
    double angle = blob.angle_deg * std::numbers::pi / 180;
    double c = std::cos(angle), s = std::sin(angle);
    double half_length = 0.5 * blob.size_px.x(), half_width = 0.5 * blob.size_px.y();
    double reach = std::max(half_length, half_width) + 1;
    Rect area = clip(blob.centre_px.x() - reach, blob.centre_px.y() - reach,
                     blob.centre_px.x() + reach, blob.centre_px.y() + reach);
    auto inside = [&](double x, double y) {
      double along = c * (x - blob.centre_px.x()) + s * (y - blob.centre_px.y());
      double across = -s * (x - blob.centre_px.x()) + c * (y - blob.centre_px.y());
      if (blob.shape == Blob::Shape::Rectangle) {
        return std::abs(along) <= half_length && std::abs(across) <= half_width;
      }
      double a = along / half_length, b = across / half_width;
      return a * a + b * b <= 1;
    };
    for (int v = area.y0; v <= area.y1; ++v) {
      for (int u = area.x0; u <= area.x1; ++u) {
        static_layer_.at<float>(v, u) +=
            static_cast<float>(blob.brightness_dn * pixel_coverage(u, v, 4, inside));
      }
    }
  }

  if (options.blur_sigma_px > 0 && (distractors.lamp || !distractors.blobs.empty())) {
    cv::GaussianBlur(static_layer_, static_layer_, cv::Size(0, 0), options.blur_sigma_px,
                     options.blur_sigma_px, cv::BORDER_REPLICATE);
  }

  cv::Mat no_noise;
  for (const Occluder& occluder : distractors.occluders) {
    // Pixels whose centres lie in [corner, corner + size).
    Rect rect = clip(std::ceil(occluder.corner_px.x()), std::ceil(occluder.corner_px.y()),
                     std::ceil(occluder.corner_px.x() + occluder.size_px.x()) - 1,
                     std::ceil(occluder.corner_px.y() + occluder.size_px.y()) - 1);
    fixed_occluders_.push_back(rect);
    occlude(rect, occluder.level_dn, no_noise, static_layer_);
  }

  if (distractors.hot_points.fixed) {
    std::mt19937_64 random(splitmix64(scene_.seed));
    std::uniform_int_distribution<int> column(0, camera_->width() - 1);
    std::uniform_int_distribution<int> row(0, camera_->height() - 1);
    for (int i = 0; i < distractors.hot_points.count; ++i) {
      int u = column(random);
      fixed_hot_points_.emplace_back(u, row(random));
    }
  }
}

void IrRenderer::begin_drawing(const cv::Rect& area) {
  for (int v = area.y; v < area.y + area.height; ++v) {
    uchar* drawn = drawn_.ptr<uchar>(v);
    float* work = work_.ptr<float>(v);
    const float* base = static_layer_.ptr<float>(v);
    const float* noise = noise_pattern_.empty() ? nullptr : noise_pattern_.ptr<float>(v);
    for (int u = area.x; u < area.x + area.width; ++u) {
      if (drawn[u]) continue;
      work[u] = noise ? base[u] + noise[u] : base[u];
      drawn[u] = 1;
    }
  }
  drawn_areas_.push_back(area);
}

void IrRenderer::mark_drawn(const cv::Rect& area) {
  drawn_(area).setTo(1);
  drawn_areas_.push_back(area);
}

void IrRenderer::occlude(const Rect& rect, double level_dn, const cv::Mat& noise,
                         cv::Mat& image) const {
  if (rect.empty()) return;
  const cv::Rect area = area_of(rect);
  double level = level_dn < 0 ? scene_.render.background_dn : level_dn;
  if (noise.empty()) {
    image(area).setTo(level);
  } else {
    cv::add(noise(area), cv::Scalar(level), image(area));
  }
}

bool IrRenderer::view_disc(const Eigen::Isometry3d& pose, const Eigen::Vector3d& marker,
                           DiscView& view) const {
  view.centre = pose * marker;
  view.normal = pose.linear().col(2);
  view.plane_offset = view.normal.dot(view.centre);
  // Seen edge-on or from behind, a marker on a board is hidden by the board.
  if (view.centre.z() < kNearestMarker_m || view.plane_offset >= 0) return false;
  Eigen::Vector3d axis_x = pose.linear().col(0), axis_y = pose.linear().col(1);
  view.x0 = view.y0 = std::numeric_limits<double>::infinity();
  view.x1 = view.y1 = -std::numeric_limits<double>::infinity();
  for (int k = 0; k < kRimSamples; ++k) {
    double angle = 2 * std::numbers::pi * k / kRimSamples;
    std::optional<Eigen::Vector2d> pixel = camera_->project(
        view.centre + marker_radius_m_ * (std::cos(angle) * axis_x + std::sin(angle) * axis_y));
    if (!pixel) return false;
    view.x0 = std::min(view.x0, pixel->x());
    view.y0 = std::min(view.y0, pixel->y());
    view.x1 = std::max(view.x1, pixel->x());
    view.y1 = std::max(view.y1, pixel->y());
  }
  view.x0 -= 1;
  view.y0 -= 1;
  view.x1 += 1;
  view.y1 += 1;
  return true;
}

void IrRenderer::add_coverage(const DiscView& view, const Rect& patch_rect, double weight,
                              cv::Mat& patch) const {
  Rect rect = clip(view.x0, view.y0, view.x1, view.y1);
  if (rect.empty()) return;
  const double radius_squared = marker_radius_m_ * marker_radius_m_;
  // Where the ray (x, y, 1) meets the disc's plane, relative to the disc's centre; NaN when it
  // misses the plane (parallel, or the plane is behind the camera along it).
  auto on_plane = [&](const Eigen::Vector2d& ray) -> Eigen::Vector3d {
    Eigen::Vector3d direction(ray.x(), ray.y(), 1);
    double along = view.normal.dot(direction);
    if (!(along < 0)) return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
    return (view.plane_offset / along) * direction - view.centre;
  };

  // The pixel corners' rays and plane points, shared by neighbouring pixels.
  int columns = rect.x1 - rect.x0 + 2, rows = rect.y1 - rect.y0 + 2;
  std::vector<Eigen::Vector2d> corner_rays(static_cast<size_t>(columns) * rows);
  std::vector<Eigen::Vector3d> corner_points(corner_rays.size());
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < columns; ++i) {
      size_t index = static_cast<size_t>(j) * columns + i;
      corner_rays[index] = rays_.corner(rect.x0 + i, rect.y0 + j);
      corner_points[index] = on_plane(corner_rays[index]);
    }
  }

  const int samples = scene_.render.supersampling;
  const double sample_weight = weight / (samples * samples);
  for (int v = rect.y0; v <= rect.y1; ++v) {
    float* row = patch.ptr<float>(v - patch_rect.y0);
    for (int u = rect.x0; u <= rect.x1; ++u) {
      size_t top_left = static_cast<size_t>(v - rect.y0) * columns + (u - rect.x0);
      std::array<size_t, 4> corners = {top_left, top_left + 1, top_left + columns,
                                       top_left + columns + 1};
      // All four corners inside the (convex) disc: the whole pixel is.
      int corners_inside = 0;
      Eigen::Vector3d middle = Eigen::Vector3d::Zero();
      for (size_t corner : corners) {
        corners_inside += corner_points[corner].squaredNorm() <= radius_squared ? 1 : 0;
        middle += 0.25 * corner_points[corner];
      }
      if (corners_inside == 4) {
        row[u - patch_rect.x0] += static_cast<float>(weight);
        continue;
      }
      // The pixel's footprint lies within `reach` of `middle`: far enough from the disc, it
      // misses it. (NaN corners fail the test and fall through to the rays.)
      double reach = 0;
      for (size_t corner : corners)
        reach = std::max(reach, (corner_points[corner] - middle).norm());
      if (middle.norm() - reach > marker_radius_m_) continue;

      const Eigen::Vector2d& r00 = corner_rays[corners[0]];
      const Eigen::Vector2d& r10 = corner_rays[corners[1]];
      const Eigen::Vector2d& r01 = corner_rays[corners[2]];
      const Eigen::Vector2d& r11 = corner_rays[corners[3]];
      int hits = 0;
      for (int j = 0; j < samples; ++j) {
        double fy = (j + 0.5) / samples;
        Eigen::Vector2d left = (1 - fy) * r00 + fy * r01;
        Eigen::Vector2d right = (1 - fy) * r10 + fy * r11;
        for (int i = 0; i < samples; ++i) {
          double fx = (i + 0.5) / samples;
          if (on_plane((1 - fx) * left + fx * right).squaredNorm() <= radius_squared) ++hits;
        }
      }
      row[u - patch_rect.x0] += static_cast<float>(hits * sample_weight);
    }
  }
}

void IrRenderer::draw_marker(const std::vector<Eigen::Isometry3d>& poses,
                             const Eigen::Vector3d& marker) {
  std::vector<DiscView> views;
  double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
  for (const Eigen::Isometry3d& pose : poses) {
    DiscView view;
    if (!view_disc(pose, marker, view)) continue;
    views.push_back(view);
    x0 = std::min(x0, view.x0);
    y0 = std::min(y0, view.y0);
    x1 = std::max(x1, view.x1);
    y1 = std::max(y1, view.y1);
  }
  if (views.empty()) return;
  double sigma = scene_.render.blur_sigma_px;
  double margin = sigma > 0 ? std::ceil(3 * sigma) + 1 : 0;
  Rect patch_rect = clip(x0 - margin, y0 - margin, x1 + margin, y1 + margin);
  if (patch_rect.empty()) return;
  const cv::Rect area = area_of(patch_rect);
  patch_.create(area.height, area.width, CV_32F);
  patch_.setTo(0);
  // A pose in which the marker is hidden still takes its share of the exposure.
  double weight = 1.0 / static_cast<double>(poses.size());
  for (const DiscView& view : views) add_coverage(view, patch_rect, weight, patch_);
  if (sigma > 0) {
    // The patch's margin holds the blurred light; beyond it there is none.
    cv::GaussianBlur(patch_, patch_, cv::Size(0, 0), sigma, sigma, cv::BORDER_CONSTANT);
  }
  begin_drawing(area);
  cv::Mat target = work_(area);
  cv::scaleAdd(patch_, peak_dn_, target, target);
}

std::vector<double> IrRenderer::exposure_times(const SceneObject& object, double time_s) const {
  double exposure_s = scene_.render.motion_blur_s;
  if (exposure_s <= 0) return {time_s};
  int steps = scene_.render.motion_blur_steps;
  if (steps == 0) {
    // Enough poses that no marker jumps more than kMotionBlurStep_px between two.
    Eigen::Isometry3d start = object_pose(object, time_s - exposure_s / 2);
    Eigen::Isometry3d middle = object_pose(object, time_s);
    Eigen::Isometry3d end = object_pose(object, time_s + exposure_s / 2);
    double travel_px = 0;
    for (const Eigen::Vector3d& marker : object.markers) {
      auto a = camera_->project(start * marker);
      auto b = camera_->project(middle * marker);
      auto c = camera_->project(end * marker);
      if (a && b && c) travel_px = std::max(travel_px, (*a - *b).norm() + (*c - *b).norm());
    }
    steps = std::clamp(static_cast<int>(std::ceil(travel_px / kMotionBlurStep_px)), 1,
                       kMaxMotionBlurSteps);
  }
  std::vector<double> times;
  for (int k = 0; k < steps; ++k) {
    times.push_back(time_s - exposure_s / 2 + (k + 0.5) * exposure_s / steps);
  }
  return times;
}

IrRenderer::Rect IrRenderer::object_occlusion(const SceneObject& object, const ObjectTruth& truth,
                                              double time_s) const {
  if (!object.occlusion || object.occlusion->fraction_at(time_s) <= 0) return {};
  double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
  double reach_px = 0;  // a marker's radius in the image, at the nearest marker
  for (size_t i = 0; i < truth.markers.size(); ++i) {
    const Eigen::Vector2d& pixel = truth.markers[i].pixel;
    if (!pixel.allFinite()) continue;
    x0 = std::min(x0, pixel.x());
    y0 = std::min(y0, pixel.y());
    x1 = std::max(x1, pixel.x());
    y1 = std::max(y1, pixel.y());
    double depth = (truth.pose * object.markers[i]).z();
    reach_px = std::max(reach_px, marker_radius_m_ * camera_->focal_length_px() / depth + 1);
  }
  if (!(x0 <= x1)) return {};
  x0 -= reach_px;
  y0 -= reach_px;
  x1 += reach_px;
  y1 += reach_px;
  double fraction = object.occlusion->fraction_at(time_s);
  switch (object.occlusion->side) {
    case ObjectOcclusion::Side::Left:
      x1 = x0 + fraction * (x1 - x0);
      break;
    case ObjectOcclusion::Side::Right:
      x0 = x1 - fraction * (x1 - x0);
      break;
    case ObjectOcclusion::Side::Top:
      y1 = y0 + fraction * (y1 - y0);
      break;
    case ObjectOcclusion::Side::Bottom:
      y0 = y1 - fraction * (y1 - y0);
      break;
  }
  return clip(x0, y0, x1, y1);
}

bool IrRenderer::hidden_by_a_board(const Eigen::Vector3d& point, size_t own,
                                   const std::vector<ObjectTruth>& objects) const {
  for (size_t o = 0; o < objects.size(); ++o) {
    if (o == own) continue;
    const Eigen::Isometry3d& pose = objects[o].pose;
    const Eigen::Vector3d normal = pose.linear().col(2);
    const double towards = normal.dot(point);
    if (std::abs(towards) < 1e-12) continue;
    // The line of sight meets the board's plane at s·point; the board hides the point when
    // that is between the camera and the point, inside the board.
    const double s = normal.dot(pose.translation()) / towards;
    if (!(s > 0 && s < 1 - 1e-9)) continue;
    const Eigen::Vector3d on_board = pose.inverse() * (s * point);
    const BoardExtent& extent = board_extents_[o];
    if (on_board.x() >= extent.x0 && on_board.x() <= extent.x1 && on_board.y() >= extent.y0 &&
        on_board.y() <= extent.y1) {
      return true;
    }
  }
  return false;
}

ObjectTruth IrRenderer::object_truth(const SceneObject& object, double time_s) const {
  ObjectTruth truth;
  truth.constellation = object.constellation;
  truth.pose = object_pose(object, time_s);
  truth.in_front = truth.pose.translation().z() > 0;
  truth.facing_camera = truth.pose.linear().col(2).dot(truth.pose.translation()) < 0;
  // Velocities by central differences over a millisecond: exact for the piecewise-smooth
  // trajectories but at their corners.
  constexpr double kStep = 5e-4;
  const Eigen::Isometry3d before = object_pose(object, time_s - kStep);
  const Eigen::Isometry3d after = object_pose(object, time_s + kStep);
  truth.linear_velocity = (after.translation() - before.translation()) / (2 * kStep);
  const Eigen::AngleAxisd turn(after.linear() * before.linear().transpose());
  truth.angular_velocity = turn.angle() * turn.axis() / (2 * kStep);
  for (const Eigen::Vector3d& marker : object.markers) {
    MarkerTruth marker_truth;
    if (auto pixel = camera_->project(truth.pose * marker)) {
      marker_truth.pixel = *pixel;
      DiscView view;
      marker_truth.visible = view_disc(truth.pose, marker, view) && camera_->in_image(*pixel);
    }
    truth.markers.push_back(marker_truth);
  }
  return truth;
}

// Hot pixels are in the sensor: they show on top of everything.
void IrRenderer::add_hot_points(std::mt19937_64& random) {
  const HotPoints& hot = scene_.distractors.hot_points;
  auto add_hot_point = [&](int u, int v) {
    begin_drawing({u, v, 1, 1});
    work_.at<float>(v, u) += static_cast<float>(hot.brightness_dn);
  };
  if (hot.fixed) {
    for (const cv::Point& point : fixed_hot_points_) add_hot_point(point.x, point.y);
  } else {
    std::uniform_int_distribution<int> column(0, camera_->width() - 1);
    std::uniform_int_distribution<int> row(0, camera_->height() - 1);
    for (int i = 0; i < hot.count; ++i) {
      int u = column(random);
      add_hot_point(u, row(random));
    }
  }
}

RenderedFrame IrRenderer::render(double time_s, uint64_t frame_number,
                                 const Eigen::Isometry3d& camera_from_world) {
  camera_from_world_ = camera_from_world;
  std::mt19937_64 random(splitmix64(scene_.seed ^ splitmix64(frame_number)));
  const int pattern = static_cast<int>(frame_number % static_cast<uint64_t>(noise_.patterns()));
  noise_pattern_ = noise_.pattern(pattern);

  RenderedFrame frame;
  frame.time_s = time_s;
  for (const SceneObject& object : scene_.objects) {
    frame.objects.push_back(object_truth(object, time_s));
  }

  // Boards are opaque: a marker whose line of sight crosses a nearer board is not drawn.
  std::vector<std::vector<bool>> behind_board(scene_.objects.size());
  for (size_t o = 0; o < scene_.objects.size(); ++o) {
    const ObjectTruth& truth = frame.objects[o];
    for (const Eigen::Vector3d& marker : scene_.objects[o].markers) {
      behind_board[o].push_back(hidden_by_a_board(truth.pose * marker, o, frame.objects));
    }
  }

  std::vector<Rect> object_occlusions;
  for (size_t o = 0; o < scene_.objects.size(); ++o) {
    const SceneObject& object = scene_.objects[o];
    ObjectTruth& truth = frame.objects[o];
    std::vector<double> times = exposure_times(object, time_s);
    std::vector<Eigen::Isometry3d> poses;
    for (double t : times) poses.push_back(object_pose(object, t));
    for (size_t m = 0; m < object.markers.size(); ++m) {
      if (behind_board[o][m]) {
        truth.markers[m].visible = false;
        continue;
      }
      draw_marker(poses, object.markers[m]);
    }
    Rect occlusion = object_occlusion(object, truth, time_s);
    if (!occlusion.empty()) object_occlusions.push_back(occlusion);
  }

  // Occluders are in front of every marker: they cover what was drawn.
  auto occlude_frame = [&](const Rect& rect, double level_dn) {
    if (rect.empty()) return;
    occlude(rect, level_dn, noise_pattern_, work_);
    mark_drawn(area_of(rect));
  };
  for (const Rect& rect : object_occlusions) occlude_frame(rect, -1);
  for (size_t k = 0; k < fixed_occluders_.size(); ++k) {
    occlude_frame(fixed_occluders_[k], scene_.distractors.occluders[k].level_dn);
  }
  auto covers = [](const Rect& rect, const Eigen::Vector2d& pixel) {
    return pixel.x() >= rect.x0 - 0.5 && pixel.x() < rect.x1 + 0.5 && pixel.y() >= rect.y0 - 0.5 &&
           pixel.y() < rect.y1 + 0.5;
  };
  for (ObjectTruth& truth : frame.objects) {
    for (MarkerTruth& marker : truth.markers) {
      for (const std::vector<Rect>* rects : {&object_occlusions, &fixed_occluders_}) {
        for (const Rect& rect : *rects) {
          if (covers(rect, marker.pixel)) marker.visible = false;
        }
      }
    }
  }

  add_hot_points(random);
  backgrounds_[static_cast<size_t>(pattern)].copyTo(frame.image);
  for (const cv::Rect& area : drawn_areas_) {
    cv::Mat target = frame.image(area);
    work_(area).convertTo(target, CV_8U);  // rounds and saturates to 0..255, as the background
    drawn_(area).setTo(0);
  }
  drawn_areas_.clear();
  return frame;
}

}  // namespace mocap::synthetic
