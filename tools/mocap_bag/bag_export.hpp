// `mocap_bag export`: a bag's bodies in a format analysis tools read (motion_export).
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace mocap::bag_export {

struct ExportOptions {
  std::string format;                 // tum or trc (c3d, csv: to come)
  std::optional<std::string> output;  // tum: a folder, one <body>.tum per body; trc: the file
  std::vector<std::string> bodies;    // empty: every body in the bag
  std::string poses_topic = "/mocap/poses";
};

// Writes the export; a one-line error on stderr and 1 for a bag without poses, a body not in it,
// or an output that cannot be written. A progress bar on stderr when it is a terminal.
int export_bag(const std::string& bag, const ExportOptions& options);

}  // namespace mocap::bag_export
