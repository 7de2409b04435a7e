#include "mocap_calibrate/board_images.hpp"

#include <fmt/format.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace mocap::calibration {

void find_board_shots(DataSpec& data, const std::string& where, bool refine) {
  const cv::Size pattern(data.board_columns, data.board_rows);
  cv::Size size;
  data.shots.clear();
  for (size_t i = 0; i < data.image_files.size(); ++i) {
    const std::string& file = data.image_files[i];
    const cv::Mat image = cv::imread(file, cv::IMREAD_GRAYSCALE);
    if (image.empty()) {
      fmt::print("skipped {}: not an image\n", file);
      continue;
    }
    if (size.area() == 0) size = image.size();
    if (image.size() != size) {
      throw CalibrationConfigError(fmt::format("{}: {} is {}x{}, but the first image is {}x{}",
                                               where, file, image.cols, image.rows, size.width,
                                               size.height));
    }
    std::vector<cv::Point2f> corners;
    if (!cv::findChessboardCorners(image, pattern, corners,
                                   cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
      fmt::print("skipped {}: no {}x{} board found\n", file, pattern.width, pattern.height);
      continue;
    }
    if (refine) {
      cv::cornerSubPix(image, corners, {5, 5}, {-1, -1},
                       {cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-3});
    }
    Shot shot;
    shot.frame = i;
    for (const cv::Point2f& p : corners) shot.points.emplace_back(p.x, p.y);
    data.shots.push_back(std::move(shot));
  }
  if (data.shots.empty()) {
    throw CalibrationConfigError(
        fmt::format("{}: none of its {} images shows the whole {}x{} board", where,
                    data.image_files.size(), pattern.width, pattern.height));
  }
  data.image_width = size.width;
  data.image_height = size.height;
}

}  // namespace mocap::calibration
