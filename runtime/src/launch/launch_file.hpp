// Launch files: the YAML that places components into process groups (launch_yaml/README.md).
#pragma once

#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <mocap/component_host.hpp>

#include "host/plugin_loader.hpp"

namespace mocap {

struct LaunchComponent {
  const LoadedPlugin* plugin = nullptr;  // null when it could not be loaded
  ComponentConfig config;
  int line = 0;  // of its name
  // Lines of its parameter, remap and QoS keys, for messages.
  std::map<std::string, int> parameter_lines;
  std::map<std::string, int> remap_lines;
  std::map<std::string, int> qos_lines;
};

struct LaunchGroup {
  std::string name;
  int threads = 0;
  // The group's own `dds: {implementation: ...}`; empty: the file's.
  std::string dds_implementation;
  // When its process dies after it has started: started again (respawn), or the deployment
  // ends (required); neither: it stays down and the others go on (group_supervisor.hpp).
  bool respawn = true;
  bool required = false;
  std::vector<LaunchComponent> components;
  int line = 0;
};

struct LaunchFile {
  std::string path;
  DdsOptions dds;
  std::vector<LaunchGroup> groups;

  const LaunchGroup* find_group(std::string_view name) const;
  // The DDS options `group`'s process runs with: the file's, with the group's implementation.
  DdsOptions dds_of(const LaunchGroup& group) const;
  size_t component_count() const;
};

// A `--set COMPONENT.PARAMETER=VALUE` option; VALUE is read as YAML (3, 0.5, true, [1, 2]).
struct ParameterOverride {
  std::string component;
  std::string parameter;
  std::string value;
  std::string text;  // as given, for messages
};

// Every problem found, each a line naming where: "demo.yaml:12: unknown parameter 'x' ...".
class LaunchError : public std::runtime_error {
 public:
  explicit LaunchError(std::vector<std::string> problems);
  const std::vector<std::string>& problems() const { return problems_; }

 private:
  std::vector<std::string> problems_;
};

// Throws LaunchError when `text` is not COMPONENT.PARAMETER=VALUE.
ParameterOverride parse_parameter_override(std::string_view text);

// Reads and validates the whole file before anything starts: YAML syntax, unknown keys,
// plugins, parameter names, types and ranges, duplicate names, topics used with two types,
// QoS that cannot match. Throws LaunchError listing every problem.
LaunchFile load_launch_file(const std::filesystem::path& path, PluginLoader& plugins,
                            const std::vector<ParameterOverride>& overrides = {});

// Every topic the file's components declare with a type, in every group, as remapped, with
// the QoS of each publisher: what Context::known_topics() reports to each group's process.
std::vector<KnownTopic> known_topics(const LaunchFile& file);

}  // namespace mocap
