#include "host/plugin_loader.hpp"

#include <dlfcn.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <map>

#include <fmt/format.h>

#include "core/names.hpp"

namespace mocap {
namespace fs = std::filesystem;

namespace {

std::string join_paths(const std::vector<fs::path>& paths) {
  std::vector<std::string> names;
  for (const fs::path& p : paths) names.push_back(p.string());
  return names.empty() ? "(empty search path)" : fmt::format("{}", fmt::join(names, ", "));
}

// lib<prefix>NAME.so files on `search_path`, by NAME; the first directory that has one wins.
std::map<std::string, fs::path> libraries_on(const std::vector<fs::path>& search_path,
                                             std::string_view prefix) {
  std::map<std::string, fs::path> libraries;
  for (const fs::path& directory : search_path) {
    std::error_code error;
    for (const auto& entry : fs::directory_iterator(directory, error)) {
      std::string file = entry.path().filename().string();
      if (file.starts_with(prefix) && file.ends_with(".so")) {
        libraries.try_emplace(file.substr(prefix.size(), file.size() - prefix.size() - 3),
                              entry.path());
      }
    }
  }
  return libraries;
}

}  // namespace

std::vector<fs::path> PluginLoader::default_search_path() {
  std::vector<fs::path> path;
  if (const char* env = std::getenv("MOCAP_PLUGIN_PATH"); env != nullptr) {
    std::string_view rest = env;
    while (!rest.empty()) {
      size_t colon = rest.find(':');
      std::string_view entry = rest.substr(0, colon);
      if (!entry.empty()) path.emplace_back(entry);
      if (colon == std::string_view::npos) break;
      rest.remove_prefix(colon + 1);
    }
  }
  std::error_code error;
  fs::path executable = fs::read_symlink("/proc/self/exe", error);
  if (!error) {
    path.push_back(
        (executable.parent_path() / ".." / "lib" / "mocap_graph" / "plugins").lexically_normal());
  }
  return path;
}

PluginLoader::PluginLoader() : PluginLoader(default_search_path()) {}

PluginLoader::PluginLoader(std::vector<fs::path> search_path)
    : search_path_(std::move(search_path)) {}

std::vector<std::string> PluginLoader::available() const {
  std::vector<std::string> names;
  for (const auto& [name, library] : libraries_on(search_path_, kPrefix)) names.push_back(name);
  return names;
}

std::vector<std::string> PluginLoader::load_message_libraries() const {
  std::vector<std::string> errors;
  for (const auto& [name, library] : libraries_on(search_path_, kMessagePrefix)) {
    // Stays loaded: the types it registers point into it.
    if (dlopen(library.c_str(), RTLD_NOW | RTLD_LOCAL) == nullptr) {
      errors.push_back(
          fmt::format("cannot load message library {}: {}", library.string(), dlerror()));
    }
  }
  return errors;
}

const LoadedPlugin& PluginLoader::load(std::string_view plugin) {
  if (auto it = loaded_.find(plugin); it != loaded_.end()) return *it->second;
  if (plugin.find('/') != std::string_view::npos) {
    fs::path library(plugin);
    // The error_code forms: a name too long for the file system is "does not exist" too,
    // not an exception out of the launch file's checks.
    std::error_code error;
    if (!fs::exists(library, error)) {
      throw PluginError(fmt::format("plugin library {} does not exist", library.string()));
    }
    return load_library(library, {});
  }
  std::string file = fmt::format("{}{}.so", kPrefix, plugin);
  for (const fs::path& directory : search_path_) {
    fs::path library = directory / file;
    std::error_code error;
    if (fs::exists(library, error)) return load_library(library, plugin);
  }
  throw PluginError(fmt::format("plugin '{}' not found: no {} in {}{}", plugin, file,
                                join_paths(search_path_),
                                did_you_mean(plugin, available(), "available plugins")));
}

const LoadedPlugin& PluginLoader::load_library(const fs::path& library,
                                               std::string_view expected_name) {
  // RTLD_LOCAL: plugins do not see each other's symbols, so two plugins may use the same
  // internal names.
  void* handle = dlopen(library.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    throw PluginError(
        fmt::format("cannot load plugin library {}: {}", library.string(), dlerror()));
  }
  dlerror();
  void* symbol = dlsym(handle, ComponentFactory::kSymbol);
  if (symbol == nullptr) {
    throw PluginError(fmt::format(
        "{} is not a mocap-graph plugin: it does not export the symbol '{}' (register the "
        "component with MOCAP_REGISTER_COMPONENT)",
        library.string(), ComponentFactory::kSymbol));
  }
  auto get_factory = reinterpret_cast<const ComponentFactory* (*)()>(symbol);
  const ComponentFactory* factory = get_factory();
  if (factory == nullptr || factory->abi_version != ComponentFactory::kAbiVersion) {
    throw PluginError(fmt::format(
        "{} was built for component ABI {}, this runtime has ABI {}; "
        "rebuild the plugin",
        library.string(), factory ? factory->abi_version : 0, ComponentFactory::kAbiVersion));
  }
  if (!expected_name.empty() && expected_name != factory->name) {
    throw PluginError(fmt::format("{} registers plugin '{}', not '{}'", library.string(),
                                  factory->name, expected_name));
  }
  auto plugin = std::make_unique<LoadedPlugin>();
  plugin->name = factory->name;
  plugin->library = library;
  plugin->factory = factory;
  try {
    factory->declare(plugin->spec);
  } catch (const std::exception& e) {
    throw PluginError(fmt::format("plugin '{}' ({}) has an invalid declaration: {}", factory->name,
                                  library.string(), e.what()));
  }
  std::string key = expected_name.empty() ? library.string() : std::string(expected_name);
  return *(loaded_[key] = std::move(plugin));
}

}  // namespace mocap
