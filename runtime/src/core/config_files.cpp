#include <mocap/config_files.hpp>

#include <dlfcn.h>

#include <cstdlib>

namespace mocap {
namespace fs = std::filesystem;

namespace {

fs::path find_config_directory() {
  if (const char* env = std::getenv("MOCAP_CONFIG_DIR"); env != nullptr && *env != '\0') {
    return env;
  }
  // An installed runtime: <prefix>/lib/libmocap_runtime.so and <prefix>/share/mocap_graph.
  Dl_info info{};
  if (dladdr(reinterpret_cast<const void*>(&find_config_directory), &info) != 0 &&
      info.dli_fname != nullptr) {
    fs::path installed =
        (fs::path(info.dli_fname).parent_path() / ".." / "share" / "mocap_graph" / "config")
            .lexically_normal();
    std::error_code error;
    if (fs::is_directory(installed, error)) return installed;
  }
  return MOCAP_SOURCE_CONFIG_DIR;
}

}  // namespace

const fs::path& config_directory() {
  static const fs::path directory = find_config_directory();
  return directory;
}

std::string config_file(std::string_view relative) {
  return (config_directory() / relative).string();
}

}  // namespace mocap
