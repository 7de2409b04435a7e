// Finds, loads and checks component plugins (shared libraries exporting a ComponentFactory).
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <mocap/component.hpp>

namespace mocap {

class PluginError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct LoadedPlugin {
  std::string name;
  std::filesystem::path library;
  const ComponentFactory* factory = nullptr;
  ComponentSpec spec;
};

// Plugin `name` lives in lib<kPrefix><name>.so. Libraries stay loaded for the life of the
// process: component code may still be referenced (vtables, static objects) at shutdown.
class PluginLoader {
 public:
  static constexpr std::string_view kPrefix = "libmocap_plugin_";

  // MOCAP_PLUGIN_PATH (colon-separated) first, then <directory of this
  // executable>/../lib/mocap_graph/plugins (the build tree and an installed tree alike).
  PluginLoader();
  explicit PluginLoader(std::vector<std::filesystem::path> search_path);

  // `plugin` is a name looked up on the search path, or a path to a library (containing
  // '/'). Throws PluginError naming the library, the symbol and the available plugins.
  const LoadedPlugin& load(std::string_view plugin);
  // Loads every lib<kMessagePrefix>*.so on the search path: the message types of projects of
  // your own (mocap_generate_messages), which register themselves with the runtime so that
  // mocap_topic and mocap_bag know them. Returns one line per library that cannot be loaded.
  static constexpr std::string_view kMessagePrefix = "libmocap_messages_";
  std::vector<std::string> load_message_libraries() const;
  // Names of the plugins found on the search path, sorted.
  std::vector<std::string> available() const;
  const std::vector<std::filesystem::path>& search_path() const { return search_path_; }

  static std::vector<std::filesystem::path> default_search_path();

 private:
  const LoadedPlugin& load_library(const std::filesystem::path& library,
                                   std::string_view expected_name);

  std::vector<std::filesystem::path> search_path_;
  std::map<std::string, std::unique_ptr<LoadedPlugin>, std::less<>> loaded_;  // by request
};

}  // namespace mocap
