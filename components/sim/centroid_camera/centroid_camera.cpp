#include "sim/centroid_camera/centroid_camera.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <span>
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

// The spheres by the columns of the image plane (x / z in the camera's frame) their shadows
// reach: a marker is tested against its column's spheres only, not against every robot.
class ShadowColumns {
 public:
  ShadowColumns(const std::vector<SphereInView>& views,
                const Eigen::Isometry3d& camera_from_world) {
    std::vector<std::pair<int, int>> reach(views.size());  // columns, first and last
    std::vector<int> counts(kColumns + 1, 0);
    for (size_t s = 0; s < views.size(); ++s) {
      const OccludingSphere& sphere = *views[s].sphere;
      const Eigen::Vector3d centre = camera_from_world * sphere.centre;
      const double r = sphere.radius_m;
      if (centre.z() - r <= 0) {
        reach[s] = {0, kColumns - 1};  // reaches behind the camera: anywhere
      } else {
        // x / z over the box around the sphere is extreme at its corners.
        const double lo =
            std::min((centre.x() - r) / (centre.z() - r), (centre.x() - r) / (centre.z() + r));
        const double hi =
            std::max((centre.x() + r) / (centre.z() - r), (centre.x() + r) / (centre.z() + r));
        reach[s] = {column_of(lo), column_of(hi)};
      }
      for (int c = reach[s].first; c <= reach[s].second; ++c) ++counts[static_cast<size_t>(c) + 1];
    }
    for (size_t c = 1; c < counts.size(); ++c) counts[c] += counts[c - 1];
    starts_ = counts;
    spheres_.resize(static_cast<size_t>(counts.back()));
    for (size_t s = 0; s < views.size(); ++s) {
      for (int c = reach[s].first; c <= reach[s].second; ++c) {
        spheres_[static_cast<size_t>(counts[static_cast<size_t>(c)]++)] = static_cast<int>(s);
      }
    }
  }

  // The spheres whose shadows may reach a point at `x_over_z`.
  std::span<const int> near(double x_over_z) const {
    const auto c = static_cast<size_t>(column_of(x_over_z));
    return {spheres_.data() + starts_[c], static_cast<size_t>(starts_[c + 1] - starts_[c])};
  }

 private:
  // Columns over x / z in [-2, 2] (63 degrees either side), the edge ones open-ended.
  static constexpr int kColumns = 80;
  static constexpr double kExtent = 2;
  static int column_of(double x_over_z) {
    const double column = std::floor((x_over_z + kExtent) / (2 * kExtent) * kColumns);
    if (!(column > 0)) return 0;
    return column < kColumns - 1 ? static_cast<int>(column) : kColumns - 1;
  }

  std::vector<int> starts_;   // column c's spheres: [starts_[c], starts_[c + 1])
  std::vector<int> spheres_;  // indices into the views
};

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
  const ShadowColumns shadows(views, camera_from_world_);
  std::vector<MarkerImage> images;
  images.reserve(markers.size());
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
        std::ranges::any_of(shadows.near(in_camera.x() / in_camera.z()), [&](int s) {
          return hidden_by(views[static_cast<size_t>(s)], centre_in_world_, markers[i], direction);
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
  // Each blob's discs together, blob by blob in the order of their roots (a counting sort).
  std::vector<int> root(images.size());
  std::vector<size_t> blob_starts(images.size() + 1, 0);
  for (size_t i = 0; i < images.size(); ++i) {
    root[i] = root_of(parent, static_cast<int>(i));
    ++blob_starts[static_cast<size_t>(root[i]) + 1];
  }
  for (size_t r = 1; r < blob_starts.size(); ++r) blob_starts[r] += blob_starts[r - 1];
  std::vector<int> in_blobs(images.size());
  std::vector<size_t> filled(blob_starts.begin(), blob_starts.end() - 1);
  for (size_t i = 0; i < images.size(); ++i) {
    in_blobs[filled[static_cast<size_t>(root[i])]++] = static_cast<int>(i);
  }

  std::normal_distribution<double> noise(0, options_.noise_px);
  std::vector<Centroid> centroids;
  centroids.reserve(images.size());
  for (size_t r = 0; r < images.size(); ++r) {
    const std::span<const int> blob(in_blobs.data() + blob_starts[r],
                                    blob_starts[r + 1] - blob_starts[r]);
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
