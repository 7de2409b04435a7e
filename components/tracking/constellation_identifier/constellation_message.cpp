#include "tracking/constellation_identifier/constellation_message.hpp"

#include <limits>

#include "tracking/constellation_database/cross_ratio.hpp"

namespace mocap::constellations {

mocap_msgs::msg::Constellation to_constellation_message(
    const IdentifiedConstellation& found, const mocap_msgs::msg::FiducialArray& array) {
  const ConstellationModel& model = *found.model;
  const auto& fiducials = array.fiducials();
  mocap_msgs::msg::Constellation constellation;
  constellation.name(model.name);
  constellation.point_names(model.line_names());
  constellation.xyz_tol(static_cast<float>(found.fit_rms_px));
  // Every line with a marker seen, its fiducials in database order; a marker not seen
  // (hidden, out of view) is a fiducial with NaN coordinates.
  for (size_t l = 0; l < model.lines.size(); ++l) {
    const ConstellationLine& model_line = model.lines[l];
    mocap_msgs::msg::SubConstellation sub;
    sub.name(model_line.name);
    sub.fiducial_array().header(array.header());
    float cx = 0, cy = 0;
    int seen = 0;
    for (int marker : model_line.points) {
      int index = found.image_point_of[marker];
      if (index < 0) {
        mocap_msgs::msg::Fiducial unseen;
        unseen.x(std::numeric_limits<float>::quiet_NaN());
        unseen.y(std::numeric_limits<float>::quiet_NaN());
        sub.fiducial_array().fiducials().push_back(unseen);
        continue;
      }
      sub.fiducial_array().fiducials().push_back(fiducials[index]);
      cx += fiducials[index].x();
      cy += fiducials[index].y();
      ++seen;
    }
    if (seen == 0) continue;
    sub.cx(cx / seen);
    sub.cy(cy / seen);
    sub.cz(0);
    // How far the measured cross-ratio is from the database's; NaN for a broken line.
    float difference = std::numeric_limits<float>::quiet_NaN();
    for (const IdentifiedLine& line : found.lines) {
      if (line.model_line == static_cast<int>(l)) {
        difference =
            static_cast<float>(relative_difference(line.cross_ratio, model_line.cross_ratio));
      }
    }
    sub.uncertainty(difference);
    constellation.sub_constellations().push_back(std::move(sub));
  }
  return constellation;
}

}  // namespace mocap::constellations
