#include "sim/centroid_camera/centroid_camera.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

namespace mocap::synthetic {
namespace {

struct MarkerImage {
  int marker = 0;
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
  double diameter_px = 0;
};

// A sphere as the camera sees it: the cone of directions it covers. A marker outside the cone
// is not behind it, which one dot product tells; only those inside get the exact test.
struct SphereInView {
  const OccludingSphere* sphere = nullptr;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // unit, camera to centre
  double cone_cosine = -1;  // of the cone's half angle; -1 with the camera in the sphere
};

SphereInView in_view(const OccludingSphere& sphere, const Eigen::Vector3d& camera) {
  SphereInView view;
  view.sphere = &sphere;
  const Eigen::Vector3d to_centre = sphere.centre - camera;
  const double distance = to_centre.norm();
  if (distance > sphere.radius_m) {
    view.direction = to_centre / distance;
    const double sine = sphere.radius_m / distance;
    view.cone_cosine = std::sqrt(1 - sine * sine);
  }
  return view;
}

bool hidden_by(const SphereInView& view, const Eigen::Vector3d& camera,
               const Eigen::Vector3d& marker, const Eigen::Vector3d& marker_direction) {
  if (view.direction.dot(marker_direction) <= view.cone_cosine) return false;
  const OccludingSphere& sphere = *view.sphere;
  // A marker on the sphere's surface (or in it) belongs to what the sphere stands for.
  if ((marker - sphere.centre).norm() <= sphere.radius_m) return false;
  const Eigen::Vector3d line = marker - camera;
  const double along = (sphere.centre - camera).dot(line) / line.squaredNorm();
  if (along <= 0 || along >= 1) return false;
  return (camera + along * line - sphere.centre).norm() < sphere.radius_m;
}

int root_of(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace

std::optional<std::string> CentroidCameraOptions::problem() const {
  if (!(marker_diameter_m > 0))
    return fmt::format("marker_diameter_m: {} is not above 0", marker_diameter_m);
  if (!(noise_px >= 0)) return fmt::format("noise_px: {} is below 0", noise_px);
  if (!(min_diameter_px > 0))
    return fmt::format("min_diameter_px: {} is not above 0", min_diameter_px);
  return std::nullopt;
}

CentroidCamera::CentroidCamera(std::shared_ptr<const calibration::CameraModel> model,
                               const Eigen::Isometry3d& camera_from_world,
                               CentroidCameraOptions options, uint64_t seed)
    : model_(std::move(model)),
      camera_from_world_(camera_from_world),
      centre_in_world_(camera_from_world.inverse().translation()),
      options_(options),
      random_(seed) {
  if (!model_) throw std::invalid_argument("CentroidCamera: no camera model");
  if (auto problem = options_.problem()) {
    throw std::invalid_argument("CentroidCameraOptions::" + *problem);
  }
}

std::vector<Centroid> CentroidCamera::project(
    const std::vector<Eigen::Vector3d>& markers, const std::vector<OccludingSphere>& spheres,
    const std::vector<Eigen::AlignedBox2d>& hidden_regions) {
  const double focal_px = model_->focal_length_px();
  std::vector<SphereInView> views;
  views.reserve(spheres.size());
  for (const OccludingSphere& sphere : spheres) views.push_back(in_view(sphere, centre_in_world_));
  std::vector<MarkerImage> images;
  for (size_t i = 0; i < markers.size(); ++i) {
    const Eigen::Vector3d in_camera = camera_from_world_ * markers[i];
    if (in_camera.z() <= 0) continue;
    const std::optional<Eigen::Vector2d> pixel = model_->project(in_camera);
    if (!pixel) continue;
    const double diameter = std::max(options_.min_diameter_px,
                                     focal_px * options_.marker_diameter_m / in_camera.norm());
    // The whole disc in the frame: a cut one's centroid is not the marker's.
    const double radius = diameter / 2;
    if (pixel->x() - radius < -0.5 || pixel->y() - radius < -0.5 ||
        pixel->x() + radius > model_->width() - 0.5 ||
        pixel->y() + radius > model_->height() - 0.5) {
      continue;
    }
    const Eigen::Vector3d direction = (markers[i] - centre_in_world_).normalized();
    if (std::any_of(hidden_regions.begin(), hidden_regions.end(),
                    [&](const Eigen::AlignedBox2d& region) { return region.contains(*pixel); }) ||
        std::any_of(views.begin(), views.end(), [&](const SphereInView& view) {
          return hidden_by(view, centre_in_world_, markers[i], direction);
        })) {
      continue;
    }
    images.push_back({static_cast<int>(i), *pixel, diameter});
  }

  // Discs that touch are one blob; sorted along x, a disc only meets those within the widest
  // diameter of it.
  std::sort(images.begin(), images.end(),
            [](const MarkerImage& a, const MarkerImage& b) { return a.pixel.x() < b.pixel.x(); });
  double widest = 0;
  for (const MarkerImage& image : images) widest = std::max(widest, image.diameter_px);
  std::vector<int> parent(images.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (size_t a = 0; a < images.size(); ++a) {
    for (size_t b = a + 1; b < images.size(); ++b) {
      if (images[b].pixel.x() - images[a].pixel.x() >= widest) break;
      const double touching = (images[a].diameter_px + images[b].diameter_px) / 2;
      if ((images[a].pixel - images[b].pixel).norm() < touching) {
        parent[root_of(parent, static_cast<int>(b))] = root_of(parent, static_cast<int>(a));
      }
    }
  }
  std::vector<std::vector<int>> blobs(images.size());
  for (size_t i = 0; i < images.size(); ++i) {
    blobs[root_of(parent, static_cast<int>(i))].push_back(static_cast<int>(i));
  }

  std::normal_distribution<double> noise(0, options_.noise_px);
  std::vector<Centroid> centroids;
  for (const std::vector<int>& blob : blobs) {
    if (blob.empty()) continue;
    Centroid centroid;
    double area = 0;
    for (int i : blob) {
      const double weight = images[i].diameter_px * images[i].diameter_px;
      centroid.pixel += weight * images[i].pixel;
      area += weight;
      centroid.markers.push_back(images[i].marker);
    }
    centroid.pixel /= area;
    double extent = 0, spread = 0;
    for (int i : blob) {
      const double off = (images[i].pixel - centroid.pixel).norm();
      extent = std::max(extent, off + images[i].diameter_px / 2);
      spread += off * off;
    }
    centroid.diameter_px = 2 * extent;
    centroid.sigma_px =
        std::hypot(options_.noise_px, std::sqrt(spread / static_cast<double>(blob.size())));
    std::sort(centroid.markers.begin(), centroid.markers.end());
    if (options_.noise_px > 0) {
      // One draw after the other: two draws in one expression happen in an order the
      // compiler picks.
      const double dx = noise(random_);
      const double dy = noise(random_);
      centroid.pixel += Eigen::Vector2d(dx, dy);
    }
    centroids.push_back(std::move(centroid));
  }
  return centroids;
}

}  // namespace mocap::synthetic
