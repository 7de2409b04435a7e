// An identified constellation as the seed's Constellation message (seed 000 §5.2.3), shared by
// the identifier and tracker plugins: each line with a marker seen, its fiducials in database
// order, NaN for a marker not seen.
#pragma once

#include <mocap_msgs/msg/constellation.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>

#include "tracking/constellation_identifier/constellation_identifier.hpp"

namespace mocap::constellations {

// `found`'s image points index `fiducials`' fiducials.
mocap_msgs::msg::Constellation to_constellation_message(
    const IdentifiedConstellation& found, const mocap_msgs::msg::FiducialArray& fiducials);

}  // namespace mocap::constellations
