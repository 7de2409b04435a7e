#include "volume/volume_calibration/calibration_messages.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <mocap/message_time.hpp>

#include "common/pose_message/pose_message.hpp"

namespace mocap::volume {

std::optional<BoardSighting> board_sighting(const mocap_msgs::msg::ConstellationArray& array,
                                            size_t camera,
                                            const constellations::ConstellationModel& board) {
  for (const auto& constellation : array.constellations()) {
    if (constellation.name() != board.name) continue;
    BoardSighting sighting;
    sighting.camera = camera;
    sighting.pixels.resize(board.points.size());
    for (const auto& line : constellation.sub_constellations()) {
      const auto model_line = std::find_if(board.lines.begin(), board.lines.end(),
                                           [&](const auto& l) { return l.name == line.name(); });
      if (model_line == board.lines.end()) continue;
      const auto& fiducials = line.fiducial_array().fiducials();
      const auto& stamp = line.fiducial_array().header().stamp();
      sighting.stamp_ns = int64_t{stamp.sec()} * 1'000'000'000 + stamp.nanosec();
      for (size_t i = 0; i < fiducials.size() && i < model_line->points.size(); ++i) {
        if (!std::isfinite(fiducials[i].x()) || !std::isfinite(fiducials[i].y())) continue;
        sighting.pixels[static_cast<size_t>(model_line->points[i])] =
            Eigen::Vector2d(fiducials[i].x(), fiducials[i].y());
      }
    }
    return sighting;
  }
  return std::nullopt;
}

mocap_msgs::msg::CalibrationCoverage coverage_message(const std::vector<CameraCoverage>& cameras,
                                                      const CoverageOptions& options,
                                                      int64_t latest_ns) {
  mocap_msgs::msg::CalibrationCoverage message;
  message.header().frame_id("world");
  message.header().stamp(
      to_time_msg(std::chrono::system_clock::time_point(std::chrono::nanoseconds(latest_ns))));
  message.progress(static_cast<float>(least_progress(cameras)));
  for (const CameraCoverage& camera : cameras) {
    mocap_msgs::msg::CameraCoverage& out = message.cameras().emplace_back();
    out.name(camera.name);
    out.image_width(static_cast<uint32_t>(camera.image_size.x()));
    out.image_height(static_cast<uint32_t>(camera.image_size.y()));
    for (size_t r = 0; r < camera.views.size(); ++r) out.views()[r] = camera.views[r];
    out.views_needed(static_cast<uint32_t>(options.views_per_region));
    out.shared_shots(camera.shared_shots);
    out.shared_shots_needed(static_cast<uint32_t>(options.shared_shots));
    out.progress(static_cast<float>(camera.progress));
    out.missing(camera.missing);
  }
  return message;
}

mocap_msgs::msg::CalibrationProgress progress_message(const SessionProgress& progress) {
  mocap_msgs::msg::CalibrationProgress message;
  message.header().stamp(to_time_msg(std::chrono::system_clock::now()));
  message.stage(progress.stage);
  message.progress(static_cast<float>(progress.fraction));
  message.detail(progress.detail);
  return message;
}

mocap_msgs::msg::VolumeCalibrationResult result_message(const CalibrationSessionResult& result) {
  mocap_msgs::msg::VolumeCalibrationResult message;
  message.header().stamp(to_time_msg(std::chrono::system_clock::now()));
  message.header().frame_id("world");
  const VolumeCalibration& calibration = result.calibration;
  message.frames_used(static_cast<uint32_t>(calibration.frames_used));
  message.rms_px(calibration.report.rms_px);
  message.points(static_cast<uint32_t>(calibration.report.points));
  message.iterations(static_cast<uint32_t>(calibration.report.iterations));
  for (size_t p = 0; p < calibration.floor.size(); ++p) {
    mocap_msgs::msg::FloorPlacement& out = message.floor().emplace_back();
    out.mark_x(result.marks[p].mark.x());
    out.mark_y(result.marks[p].mark.y());
    out.cameras(static_cast<uint32_t>(calibration.floor[p].cameras));
    out.rms_px(calibration.floor[p].rms_px);
    out.off_mark_m(calibration.floor.size() > 1 ? calibration.floor[p].off_mark_m : -1.0);
  }
  for (const CalibratedCamera& camera : result.cameras) {
    mocap_msgs::msg::CalibratedCamera& out = message.cameras().emplace_back();
    out.name(camera.name);
    out.rms_px(camera.rms_px);
    out.shots(static_cast<uint32_t>(camera.shots));
    out.pose(to_pose_message(camera.world_from_camera));
    out.has_previous_pose(camera.previous.has_value());
    if (camera.previous) out.previous_pose(to_pose_message(*camera.previous));
    out.moved_m(camera.moved_m);
    out.turned_deg(camera.turned_deg);
    out.file(camera.file);
  }
  return message;
}

}  // namespace mocap::volume
