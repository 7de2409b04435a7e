// mocap_topic doctor's gathering: a few seconds on the DDS domain (its endpoints, every
// process's /diagnostics, their clocks by probe), the discovery traffic of a range of domains,
// and the launch file's expectations; then doctor.hpp's findings, printed one per line.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace mocap::doctor {

struct DoctorCommand {
  std::optional<std::string> launch_file;
  std::vector<int> domains;  // to listen to besides the graph's; empty: 0 to 9
  double seconds = 4;
  std::string security_directory;
  std::string security_identity;
};

// Prints the findings; 0 when all is well, 1 when something is wrong, 2 when the doctor itself
// cannot run (a launch file that does not load, a port it cannot open).
int run_doctor(const DoctorCommand& command);

}  // namespace mocap::doctor
