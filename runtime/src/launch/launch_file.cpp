#include "launch/launch_file.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include <mocap/config_reader.hpp>
#include "core/names.hpp"
#include "dds/dds_options.hpp"
#include "dds/dds_transport.hpp"
#include "host/dds_implementations.hpp"
#include "launch/yaml_value.hpp"

namespace mocap {
namespace {

int line_of(const YAML::Node& node) { return node.Mark().line + 1; }

// Every problem of the file, in file order; those of --set options last.
using Problems = ConfigReader<ConfigError>;

// Records repeated keys and, when `allowed` is given, keys outside it. `what` names the map in
// messages.
void check_keys(const YAML::Node& map, const std::optional<std::vector<std::string>>& allowed,
                std::string_view what, Problems& problems) {
  problems.report_keys(map, allowed ? &*allowed : nullptr, what);
}

std::optional<std::string> string_value(const YAML::Node& node, std::string_view key,
                                        Problems& problems) {
  if (!node.IsScalar()) {
    problems.record(node, fmt::format("'{}' must be a text value", key));
    return std::nullopt;
  }
  return node.Scalar();
}

std::optional<int64_t> int_value(const YAML::Node& node, std::string_view key, int64_t min,
                                 int64_t max, Problems& problems) {
  try {
    ParameterValue value = parameter_value_from_yaml(node);
    if (const int64_t* number = std::get_if<int64_t>(&value);
        number && *number >= min && *number <= max) {
      return *number;
    }
  } catch (const std::invalid_argument&) {
  }
  problems.record(node, fmt::format("'{}' must be an integer in [{}, {}]", key, min, max));
  return std::nullopt;
}

std::optional<bool> bool_value(const YAML::Node& node, std::string_view key, Problems& problems) {
  try {
    ParameterValue value = parameter_value_from_yaml(node);
    if (const bool* flag = std::get_if<bool>(&value)) return *flag;
  } catch (const std::invalid_argument&) {
  }
  problems.record(node, fmt::format("'{}' must be true or false", key));
  return std::nullopt;
}

std::optional<Qos> qos_value(const YAML::Node& node, std::string_view topic, Problems& problems) {
  auto unknown_profile = [&](const YAML::Node& at, const std::string& name) {
    problems.record(at, fmt::format("QoS for '{}': unknown profile '{}' (profiles: {})", topic,
                                    name, Qos::profile_names));
  };
  if (node.IsScalar()) {
    if (auto qos = Qos::from_profile(node.Scalar())) return qos;
    unknown_profile(node, node.Scalar());
    return std::nullopt;
  }
  if (!node.IsMap()) {
    problems.record(node, fmt::format("QoS for '{}' must be a profile name or {{profile, depth, "
                                      "max_blocking_s}}",
                                      topic));
    return std::nullopt;
  }
  check_keys(node, std::vector<std::string>{"profile", "depth", "max_blocking_s"},
             fmt::format("the QoS of '{}'", topic), problems);
  std::optional<Qos> qos;
  if (YAML::Node profile = node["profile"]) {
    if (!profile.IsScalar() || !(qos = Qos::from_profile(profile.Scalar()))) {
      unknown_profile(profile, profile.IsScalar() ? profile.Scalar() : "?");
      return std::nullopt;
    }
  } else {
    problems.record(node, fmt::format("QoS for '{}' needs a 'profile'", topic));
    return std::nullopt;
  }
  if (YAML::Node depth = node["depth"]) {
    auto value = int_value(depth, "depth", 1, 1000000, problems);
    if (!value) return std::nullopt;
    qos->depth = static_cast<int>(*value);
  }
  if (YAML::Node limit = node["max_blocking_s"]) {
    if (!publisher_may_wait(*qos, *qos)) {
      problems.record(limit, fmt::format("QoS for '{}': max_blocking_s applies to the reliable "
                                         "profile (keep_all), not to {}",
                                         topic, node["profile"].Scalar()));
      return std::nullopt;
    }
    std::optional<double> seconds;
    try {
      ParameterValue value = parameter_value_from_yaml(limit);
      if (const double* number = std::get_if<double>(&value)) seconds = *number;
      if (const int64_t* number = std::get_if<int64_t>(&value)) seconds = *number;
    } catch (const std::invalid_argument&) {
    }
    if (!seconds || !(*seconds >= 0.001 && *seconds <= 3600)) {
      problems.record(limit, "'max_blocking_s' must be a number of seconds in [0.001, 3600]");
      return std::nullopt;
    }
    qos->max_blocking = std::chrono::milliseconds(std::llround(*seconds * 1000));
  }
  return qos;
}

struct TopicUse {
  const TopicSpec* spec;
  Qos qos;
  const LaunchComponent* component;
};

// Subscribers in `subscribers` that no publisher in `publishers` can serve.
void check_qos(const std::string& topic, const std::vector<TopicUse>& subscribers,
               const std::vector<TopicUse>& publishers, Problems& problems) {
  for (const TopicUse& subscriber : subscribers) {
    if (subscriber.spec->direction != TopicDirection::Subscribe) continue;
    for (const TopicUse& publisher : publishers) {
      if (publisher.spec->direction != TopicDirection::Publish) continue;
      if (auto why = qos_mismatch(publisher.qos, subscriber.qos)) {
        problems.record(subscriber.component->line,
                        fmt::format("topic '{}': component '{}' ({}) would receive nothing from "
                                    "component '{}' (line {}, {}): {}",
                                    topic, subscriber.component->config.name,
                                    subscriber.qos.to_string(), publisher.component->config.name,
                                    publisher.component->line, publisher.qos.to_string(), *why));
      }
    }
  }
}

// Checks across the whole file (every group): one type per topic, and QoS that can match.
void check_topics(const std::vector<const LaunchComponent*>& components, Problems& problems) {
  using Use = TopicUse;
  std::map<std::string, std::vector<Use>> uses;
  for (const LaunchComponent* component : components) {
    const ComponentConfig& config = component->config;
    for (const TopicSpec& topic : component->plugin->spec.topics()) {
      if (topic.type == nullptr) continue;  // any topic: checked when used
      auto remap = config.remaps.find(topic.topic);
      auto qos = config.qos.find(topic.topic);
      uses[remap == config.remaps.end() ? topic.topic : remap->second].push_back(
          {&topic, qos == config.qos.end() ? topic.qos : qos->second, component});
    }
  }
  // A family ("/pixart/{camera}/fiducials") shares its type and QoS rules with every topic
  // it can produce, so uses are compared across overlapping names, not only equal ones.
  for (auto a = uses.begin(); a != uses.end(); ++a) {
    for (auto b = a; b != uses.end(); ++b) {
      if (!topics_overlap(a->first, b->first)) continue;
      const std::string& topic = a->first == b->first ? a->first : b->first;
      const Use& first = a->second.front();
      for (const Use& use : b->second) {
        if (use.spec->type != first.spec->type) {
          problems.record(use.component->line,
                          fmt::format("topic '{}' is {} for component '{}' but {} for component "
                                      "'{}' (line {})",
                                      topic, use.spec->type->name(), use.component->config.name,
                                      first.spec->type->name(), first.component->config.name,
                                      first.component->line));
          break;
        }
      }
      check_qos(topic, a->second, b->second, problems);
      if (a != b) check_qos(topic, b->second, a->second, problems);
    }
  }
}

class Reader {
 public:
  Reader(std::string file, PluginLoader& plugins) : problems_(file), plugins_(plugins) {
    result_.path = std::move(file);
  }

  LaunchFile read(const YAML::Node& root, const std::vector<ParameterOverride>& overrides) {
    if (!root.IsMap()) {
      problems_.record(root, "a launch file is a map with 'groups' (and optionally 'dds')");
      throw LaunchError(problems_.problems());
    }
    check_keys(root, std::vector<std::string>{"dds", "groups"}, "the launch file", problems_);
    if (YAML::Node dds = root["dds"]) read_dds(dds);
    YAML::Node groups = root["groups"];
    if (!groups || !groups.IsSequence() || groups.size() == 0) {
      problems_.record(groups ? groups : root, "'groups' must be a non-empty list of groups");
    } else {
      for (const YAML::Node& group : groups) read_group(group);
    }
    apply(overrides);
    // With every value in place, check each component against its plugin's declaration.
    std::vector<const LaunchComponent*> loaded;
    for (LaunchGroup& group : result_.groups) {
      for (LaunchComponent& component : group.components) {
        if (component.plugin == nullptr) continue;
        check_component(component);
        resolve_paths(component);
        loaded.push_back(&component);
      }
    }
    check_topics(loaded, problems_);
    check_implementations();
    if (!problems_.problems().empty()) throw LaunchError(problems_.problems());
    return std::move(result_);
  }

 private:
  void read_dds(const YAML::Node& dds) {
    if (!dds.IsMap()) {
      problems_.record(dds,
                       "'dds' must be a map (implementation, enabled, domain_id, shared_memory, "
                       "discovery, security)");
      return;
    }
    check_keys(dds,
               std::vector<std::string>{"implementation", "enabled", "domain_id", "shared_memory",
                                        "discovery", "security"},
               "'dds'", problems_);
    if (YAML::Node n = dds["implementation"]) {
      result_.dds.implementation = implementation_value(n);
      implementation_line_ = line_of(n);
    }
    if (YAML::Node n = dds["enabled"]) {
      if (auto v = bool_value(n, "enabled", problems_)) result_.dds.enabled = *v;
    }
    if (YAML::Node n = dds["domain_id"]) {
      if (auto v = int_value(n, "domain_id", 0, 232, problems_)) result_.dds.domain_id = int(*v);
    }
    if (YAML::Node n = dds["shared_memory"]) {
      if (auto v = bool_value(n, "shared_memory", problems_)) result_.dds.shared_memory = *v;
    }
    if (YAML::Node n = dds["discovery"]) {
      read_discovery(n);
      discovery_line_ = line_of(n);
    }
    if (YAML::Node n = dds["security"]) {
      security_line_ = line_of(n);
      read_security(n);
    }
  }

  // The name of an implementation; "" (and a problem) for anything else.
  std::string implementation_value(const YAML::Node& node) {
    std::string name = string_value(node, "implementation", problems_).value_or("");
    try {
      if (!name.empty()) return std::string(resolve_dds_implementation(name).name);
    } catch (const std::runtime_error& e) {
      problems_.record(node, e.what());
    }
    return "";
  }

  // What a group's implementation cannot do (DdsFeature): discovery servers, and DDS
  // Security's handshake with groups on another implementation.
  void check_implementations() {
    // Implementation -> its first group.
    std::map<std::string_view, const LaunchGroup*> first_on;
    for (const LaunchGroup& group : result_.groups) {
      const DdsImplementation* implementation = nullptr;
      try {
        implementation = &resolve_dds_implementation(result_.dds_of(group).implementation);
      } catch (const std::runtime_error& e) {
        problems_.record(group.line, e.what());
        continue;
      }
      first_on.emplace(implementation->name, &group);
      if (!implementation->supports(DdsFeature::kDiscoveryServers) &&
          !result_.dds.discovery_servers.empty()) {
        problems_.record(discovery_line_,
                         fmt::format("dds.discovery.server: {} has no discovery servers (group "
                                     "'{}'{}); run that group on an implementation that has "
                                     "them ({}), or use multicast discovery (launch_yaml/README.md "
                                     "says how to give it its peers instead)",
                                     implementation->name, group.name, where_chosen(group),
                                     implementations_with(DdsFeature::kDiscoveryServers)));
      }
    }
    if (result_.dds.security_identity.empty()) return;
    auto governance = security_files(result_.dds.security_directory, "").governance;
    for (const auto& [name, group] : first_on) {
      if (auto problem = resolve_dds_implementation(name).governance_problem(governance)) {
        problems_.record(security_line_, fmt::format("dds.security: {} (group '{}' runs on {})",
                                                     *problem, group->name, name));
      }
    }
    // One identity on both sides: which side starts the handshake is chance, and an
    // implementation without kSecurityHandshakeWithOthers fails when it starts it
    // (launch_yaml/README.md).
    for (const auto& [name, group] : first_on) {
      if (resolve_dds_implementation(name).supports(DdsFeature::kSecurityHandshakeWithOthers)) {
        continue;
      }
      for (const auto& [other_name, other] : first_on) {
        if (other_name == name) continue;
        problems_.record(
            security_line_,
            fmt::format("dds.security: group '{}' ({}{}) and group '{}' ({}{}) would "
                        "authenticate each other only when the {} side starts the handshake, "
                        "which with one identity is chance; run them on one implementation, or "
                        "in separate launch files with identities ordered as "
                        "launch_yaml/README.md explains",
                        group->name, name, where_chosen(*group), other->name, other_name,
                        where_chosen(*other), other_name));
      }
    }
  }

  // The implementations that have `feature`, for messages: "fastdds".
  static std::string implementations_with(DdsFeature feature) {
    std::vector<std::string_view> names;
    for (const DdsImplementation& implementation : dds_implementations()) {
      if (implementation.supports(feature)) names.push_back(implementation.name);
    }
    return names.empty() ? "none here" : fmt::format("{}", fmt::join(names, ", "));
  }

  // Where a group's implementation comes from, for messages: ", line N" or ", from
  // MOCAP_DDS_IMPLEMENTATION".
  std::string where_chosen(const LaunchGroup& group) const {
    if (!group.dds_implementation.empty()) return fmt::format(", line {}", group.line);
    if (implementation_line_ > 0) return fmt::format(", line {}", implementation_line_);
    return ", from MOCAP_DDS_IMPLEMENTATION";
  }

  // discovery: {server: "host:port"} or {server: ["host:port", ...]}
  void read_discovery(const YAML::Node& node) {
    if (!node.IsMap()) {
      problems_.record(node, "dds.discovery must be a map with 'server'");
      return;
    }
    check_keys(node, std::vector<std::string>{"server"}, "'dds.discovery'", problems_);
    YAML::Node server = node["server"];
    std::vector<YAML::Node> entries;
    if (server && server.IsScalar()) {
      entries.push_back(server);
    } else if (server && server.IsSequence() && server.size() > 0) {
      for (const YAML::Node& entry : server) entries.push_back(entry);
    } else {
      problems_.record(server ? server : node,
                       "dds.discovery.server must be \"host:port\" or a non-empty list of them");
      return;
    }
    for (const YAML::Node& entry : entries) {
      if (entry.IsScalar() && parse_host_port(entry.Scalar())) {
        result_.dds.discovery_servers.push_back(entry.Scalar());
      } else {
        problems_.record(entry, fmt::format("dds.discovery.server: '{}' is not host:port",
                                            entry.IsScalar() ? entry.Scalar() : "?"));
      }
    }
  }

  // security: {directory: PATH, identity: NAME}; a relative PATH is taken from the file's folder.
  void read_security(const YAML::Node& node) {
    if (!node.IsMap()) {
      problems_.record(node, "dds.security must be a map with 'directory' and 'identity'");
      return;
    }
    check_keys(node, std::vector<std::string>{"directory", "identity"}, "'dds.security'",
               problems_);
    YAML::Node directory = node["directory"];
    YAML::Node identity = node["identity"];
    if (!directory || !identity) {
      problems_.record(node, "dds.security needs 'directory' and 'identity'");
      return;
    }
    auto folder = string_value(directory, "dds.security.directory", problems_);
    auto name = string_value(identity, "dds.security.identity", problems_);
    if (!folder || !name) return;
    namespace fs = std::filesystem;
    fs::path path(*folder);
    if (path.is_relative()) path = fs::absolute(result_.path).parent_path() / path;
    path = path.lexically_normal();
    if (auto problem = check_security(path, *name)) {
      problems_.record(problem->key == "directory" ? directory : identity,
                       fmt::format("dds.security.{}: {}", problem->key, problem->message));
      return;
    }
    result_.dds.security_directory = path.string();
    result_.dds.security_identity = *name;
  }

  void read_group(const YAML::Node& node) {
    if (!node.IsMap()) {
      problems_.record(node, "a group is a map with 'name' and 'components'");
      return;
    }
    LaunchGroup group;
    group.line = line_of(node);
    check_keys(
        node,
        std::vector<std::string>{"name", "threads", "dds", "respawn", "required", "components"},
        "a group", problems_);
    if (YAML::Node dds = node["dds"]) {
      if (!dds.IsMap()) {
        problems_.record(dds, "a group's 'dds' must be a map with 'implementation'");
      } else {
        check_keys(dds, std::vector<std::string>{"implementation"}, "a group's 'dds'", problems_);
        if (YAML::Node n = dds["implementation"])
          group.dds_implementation = implementation_value(n);
      }
    }
    if (YAML::Node name = node["name"]) {
      group.name = string_value(name, "name", problems_).value_or("");
      if (!valid_component_name(group.name)) {
        problems_.record(
            name, fmt::format("group name '{}' must use letters, digits, '_' and '-'", group.name));
      }
      for (const LaunchGroup& other : result_.groups) {
        if (other.name == group.name) {
          problems_.record(name, fmt::format("duplicate group name '{}' (first at line {})",
                                             group.name, other.line));
        }
      }
    } else {
      problems_.record(node, "a group needs a 'name'");
    }
    if (YAML::Node threads = node["threads"]) {
      group.threads =
          static_cast<int>(int_value(threads, "threads", 1, 256, problems_).value_or(0));
    }
    if (YAML::Node respawn = node["respawn"]) {
      group.respawn = bool_value(respawn, "respawn", problems_).value_or(true);
    }
    if (YAML::Node required = node["required"]) {
      group.required = bool_value(required, "required", problems_).value_or(false);
      if (group.required && node["respawn"] && group.respawn) {
        problems_.record(required, fmt::format("group '{}': 'required' ends the deployment when "
                                               "it dies, 'respawn' restarts it: choose one",
                                               group.name));
      }
    }
    YAML::Node components = node["components"];
    bool has_components = components && components.IsSequence() && components.size() > 0;
    if (!has_components) {
      problems_.record(components ? components : node,
                       fmt::format("group '{}' needs 'components', a non-empty list", group.name));
    }
    result_.groups.push_back(std::move(group));  // read_component() adds to the last group
    if (has_components) {
      for (const YAML::Node& component : components) read_component(component);
    }
  }

  void read_component(const YAML::Node& node) {
    if (!node.IsMap()) {
      problems_.record(node, "a component is a map with 'plugin' and 'name'");
      return;
    }
    check_keys(node, std::vector<std::string>{"plugin", "name", "parameters", "remap", "qos"},
               "a component", problems_);
    LaunchComponent component;
    component.line = line_of(node);
    YAML::Node name = node["name"];
    if (!name) {
      problems_.record(node, "a component needs a 'name'");
    } else if (auto text = string_value(name, "name", problems_)) {
      component.config.name = *text;
      component.line = line_of(name);
      if (!valid_component_name(*text)) {
        problems_.record(name, fmt::format("component name '{}' must use letters, digits, '_' "
                                           "and '-'",
                                           *text));
      }
      if (auto [it, fresh] = component_lines_.emplace(*text, component.line); !fresh) {
        problems_.record(name, fmt::format("duplicate component name '{}' (first at line {})",
                                           *text, it->second));
      }
    }
    YAML::Node plugin = node["plugin"];
    if (!plugin) {
      problems_.record(node, "a component needs a 'plugin'");
    } else if (auto text = string_value(plugin, "plugin", problems_)) {
      try {
        component.plugin = &plugins_.load(*text);
      } catch (const PluginError& e) {
        problems_.record(plugin, e.what());
      }
    }
    std::string who = fmt::format("component '{}'", component.config.name);
    if (YAML::Node parameters = node["parameters"]) {
      if (!parameters.IsMap()) {
        problems_.record(parameters, "'parameters' must be a map of name: value");
      } else {
        check_keys(parameters, std::nullopt, "'parameters'", problems_);
        for (const auto& entry : parameters) {
          if (!entry.first.IsScalar()) continue;  // reported by check_keys
          std::string key = entry.first.Scalar();
          try {
            component.config.parameters[key] = parameter_value_from_yaml(entry.second);
            component.parameter_lines[key] = line_of(entry.first);
          } catch (const std::invalid_argument& e) {
            problems_.record(entry.second,
                             fmt::format("{}: parameter '{}' has {}", who, key, e.what()));
          }
        }
      }
    }
    if (YAML::Node remap = node["remap"]) {
      read_topic_map(remap, "remap", component.remap_lines,
                     [&](const std::string& from, const YAML::Node& to) {
                       if (auto text = string_value(to, "remap target", problems_)) {
                         component.config.remaps[from] = *text;
                       }
                     });
    }
    if (YAML::Node qos = node["qos"]) {
      read_topic_map(qos, "qos", component.qos_lines,
                     [&](const std::string& topic, const YAML::Node& value) {
                       if (auto parsed = qos_value(value, topic, problems_))
                         component.config.qos[topic] = *parsed;
                     });
    }
    result_.groups.back().components.push_back(std::move(component));
  }

  template <class Each>
  void read_topic_map(const YAML::Node& map, std::string_view key,
                      std::map<std::string, int>& lines, Each each) {
    if (!map.IsMap()) {
      problems_.record(map, fmt::format("'{}' must be a map of topic: value", key));
      return;
    }
    check_keys(map, std::nullopt, fmt::format("'{}'", key), problems_);
    for (const auto& entry : map) {
      if (!entry.first.IsScalar()) continue;  // reported by check_keys
      std::string topic = entry.first.Scalar();
      lines[topic] = line_of(entry.first);
      each(topic, entry.second);
    }
  }

  void apply(const std::vector<ParameterOverride>& overrides) {
    for (const ParameterOverride& o : overrides) {
      LaunchComponent* target = nullptr;
      for (LaunchGroup& group : result_.groups) {
        for (LaunchComponent& component : group.components) {
          if (component.config.name == o.component && target == nullptr) target = &component;
        }
      }
      if (target == nullptr) {
        problems_.record_outside(fmt::format("--set {}: no component named '{}' in {}", o.text,
                                             o.component, result_.path));
        continue;
      }
      try {
        target->config.parameters[o.parameter] = parameter_value_from_yaml(YAML::Load(o.value));
        set_texts_[{target, o.parameter}] = o.text;
      } catch (const std::exception& e) {
        problems_.record_outside(
            fmt::format("--set {}: the value is not valid: {}", o.text, e.what()));
      }
    }
  }

  // Relative paths from the file are relative to the file, from --set to the working directory,
  // so a launch file works from any directory.
  void resolve_paths(LaunchComponent& component) {
    namespace fs = std::filesystem;
    for (auto& [name, value] : component.config.parameters) {
      const ParameterSpec* spec = component.plugin->spec.find_parameter(name);
      if (spec == nullptr || !spec->is_path) continue;
      bool from_set = set_texts_.count({&component, name}) > 0;
      fs::path base = from_set ? fs::current_path() : fs::absolute(result_.path).parent_path();
      auto resolve = [&base](std::string& text) {
        if (!text.empty() && !fs::path(text).is_absolute()) {
          text = (base / fs::path(text)).lexically_normal().string();
        }
      };
      if (auto* text = std::get_if<std::string>(&value)) resolve(*text);
      if (auto* texts = std::get_if<std::vector<std::string>>(&value)) {
        for (std::string& text : *texts) resolve(text);
      }
    }
  }

  void check_component(const LaunchComponent& component) {
    const ComponentSpec& spec = component.plugin->spec;
    const ComponentConfig& config = component.config;
    std::string who = fmt::format("component '{}' ({})", config.name, component.plugin->name);
    // One config at a time, so each problem gets the line of its own key.
    for (const auto& [name, value] : config.parameters) {
      ComponentConfig one{config.name, {{name, value}}, {}, {}};
      for (const std::string& problem : check_component_config(spec, one)) {
        if (auto set = set_texts_.find({&component, name}); set != set_texts_.end()) {
          problems_.record_outside(fmt::format("--set {}: {}: {}", set->second, who, problem));
        } else {
          problems_.record(component.parameter_lines.at(name), fmt::format("{}: {}", who, problem));
        }
      }
    }
    for (const auto& [from, to] : config.remaps) {
      ComponentConfig one{config.name, {}, {{from, to}}, {}};
      for (const std::string& problem : check_component_config(spec, one)) {
        problems_.record(component.remap_lines.at(from), fmt::format("{}: {}", who, problem));
      }
    }
    for (const auto& [topic, qos] : config.qos) {
      ComponentConfig one{config.name, {}, {}, {{topic, qos}}};
      for (const std::string& problem : check_component_config(spec, one)) {
        problems_.record(component.qos_lines.at(topic), fmt::format("{}: {}", who, problem));
      }
    }
  }

  Problems problems_;
  PluginLoader& plugins_;
  LaunchFile result_;
  int implementation_line_ = 0;  // of dds.implementation, when given
  int discovery_line_ = 0;       // of dds.discovery, when given
  int security_line_ = 0;        // of dds.security, when given
  std::map<std::string, int> component_lines_;
  // The --set option behind each overridden parameter.
  std::map<std::pair<const LaunchComponent*, std::string>, std::string> set_texts_;
};

}  // namespace

LaunchError::LaunchError(std::vector<std::string> problems)
    : std::runtime_error(problems.empty() ? "invalid launch file" : problems.front()),
      problems_(std::move(problems)) {}

const LaunchGroup* LaunchFile::find_group(std::string_view name) const {
  for (const LaunchGroup& group : groups) {
    if (group.name == name) return &group;
  }
  return nullptr;
}

DdsOptions LaunchFile::dds_of(const LaunchGroup& group) const {
  DdsOptions options = dds;
  if (!group.dds_implementation.empty()) options.implementation = group.dds_implementation;
  return options;
}

size_t LaunchFile::component_count() const {
  size_t count = 0;
  for (const LaunchGroup& group : groups) count += group.components.size();
  return count;
}

ParameterOverride parse_parameter_override(std::string_view text) {
  size_t equals = text.find('=');
  size_t dot = text.substr(0, equals).find('.');
  if (equals == std::string_view::npos || dot == std::string_view::npos || dot == 0 ||
      dot + 1 == equals) {
    throw LaunchError({fmt::format("--set {}: expected COMPONENT.PARAMETER=VALUE", text)});
  }
  return {std::string(text.substr(0, dot)), std::string(text.substr(dot + 1, equals - dot - 1)),
          std::string(text.substr(equals + 1)), std::string(text)};
}

LaunchFile load_launch_file(const std::filesystem::path& path, PluginLoader& plugins,
                            const std::vector<ParameterOverride>& overrides) {
  std::ifstream stream(path);
  if (!stream) {
    throw LaunchError(
        {fmt::format("{}: cannot read the launch file: {}", path.string(), std::strerror(errno))});
  }
  std::stringstream text;
  text << stream.rdbuf();
  try {
    YAML::Node root = Problems(path.string()).parse(text.str());
    return Reader(path.string(), plugins).read(root, overrides);
  } catch (const ConfigError& e) {
    throw LaunchError({e.what()});
  } catch (const YAML::Exception& e) {
    // Syntax errors, and anything else yaml-cpp refuses, with the place it names.
    throw LaunchError({fmt::format("{}:{}:{}: YAML error: {}", path.string(), e.mark.line + 1,
                                   e.mark.column + 1, e.msg)});
  }
}

std::vector<KnownTopic> known_topics(const LaunchFile& file) {
  std::map<std::string, KnownTopic> known;
  for (const LaunchGroup& group : file.groups) {
    for (const LaunchComponent& component : group.components) {
      if (component.plugin == nullptr) continue;
      const ComponentConfig& config = component.config;
      for (const TopicSpec& declared : component.plugin->spec.topics()) {
        if (declared.type == nullptr) continue;
        auto remap = config.remaps.find(declared.topic);
        const std::string& name = remap == config.remaps.end() ? declared.topic : remap->second;
        KnownTopic& topic = known[name];
        if (topic.type == nullptr) {
          topic.topic = name;
          topic.type = declared.type;
        }
        if (declared.direction == TopicDirection::Publish) {
          auto qos = config.qos.find(declared.topic);
          topic.publishers.push_back(qos == config.qos.end() ? declared.qos : qos->second);
        }
      }
    }
  }
  std::vector<KnownTopic> topics;
  for (auto& [name, topic] : known) topics.push_back(std::move(topic));
  return topics;
}

}  // namespace mocap
