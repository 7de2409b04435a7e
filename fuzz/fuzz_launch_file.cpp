// Launch YAML: whatever the file holds, load_launch_file() either returns a validated file or
// throws LaunchError with its problems, each naming the file; nothing else may escape.
// The shipped plugins are on the search path, so parameters and topics are checked for real.
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "fuzz/scratch_files.hpp"
#include "host/plugin_loader.hpp"
#include "launch/launch_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  // A plugin named by path loads that library: any shared object on the machine. Not a
  // parser's input; such files are left out.
  if (text.find(".so") != std::string_view::npos) return 0;
  static mocap::PluginLoader plugins({MOCAP_FUZZ_PLUGIN_DIR});
  const std::filesystem::path file = fuzz::fresh_scratch_folder("fuzz_launch_file") / "f.yaml";
  {
    std::ofstream out(file, std::ios::binary);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
  }
  try {
    mocap::load_launch_file(file, plugins);
  } catch (const mocap::LaunchError& error) {
    // Every problem names the file, so a user with several knows which to open.
    if (error.problems().empty()) std::abort();
    for (const std::string& problem : error.problems()) {
      if (problem.find("f.yaml") == std::string::npos) std::abort();
    }
  }
  return 0;
}
