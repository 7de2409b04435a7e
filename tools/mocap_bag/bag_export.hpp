// `mocap_bag export`: a bag's bodies, and with --markers its marker cloud, in a format analysis
// tools read (motion_export).
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace mocap::bag_export {

struct ExportOptions {
  std::string format;                 // c3d, trc, csv or tum
  std::optional<std::string> output;  // tum: a folder, one <body>.tum per body; else the file
  std::vector<std::string> bodies;    // empty: every body in the bag
  // The marker cloud too (c3d, trc, csv): labeled markers as "<body>_<n>", the others as
  // "unlabeled_<track>".
  bool markers = false;
  // The fusion's bodies and robots files of the recording: a cloud names a marker's body by its
  // index in their list (bodies, then robots). Without them, "body<index>".
  std::optional<std::string> bodies_file, robots_file;
  std::string poses_topic = "/mocap/poses";
  std::string markers_topic = "/mocap/markers";
};

// Writes the export; a one-line error on stderr and 1 for a bag without poses, a body not in it,
// or an output that cannot be written; 2 for a format it does not know. A progress bar on stderr
// when it is a terminal.
int export_bag(const std::string& bag, const ExportOptions& options);

}  // namespace mocap::bag_export
