// The shipped configuration files (cameras, constellations, rigs, scenes, turret) that
// plugins offer as parameter defaults.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace mocap {

// The directory of the shipped configuration: $MOCAP_CONFIG_DIR when set; in an installed
// tree, share/mocap_graph/config next to the lib/ this runtime library was loaded from; in a
// build tree, the source tree's config/. Decided once per process.
const std::filesystem::path& config_directory();

// config_directory() / relative, e.g. config_file("cameras/synthetic_ir_1280x720.yaml").
std::string config_file(std::string_view relative);

}  // namespace mocap
