// mocap_launch: validates and runs launch files; documents plugins.
#include <unistd.h>

#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <mocap/component_host.hpp>
#include <mocap/launch_start.hpp>

#include "host/plugin_loader.hpp"
#include "launch/group_supervisor.hpp"
#include "launch/launch_file.hpp"
#include "mocap_launch/launch_alerts.hpp"

namespace {

constexpr const char* kDiagnosticsPlugin = "diagnostics";

constexpr const char* kUsage = R"(usage:
  mocap_launch FILE [--group NAME] [--set COMPONENT.PARAM=VALUE]... [--duration SECONDS]
               [--health-file PATH] [--check]
  mocap_launch --describe PLUGIN
  mocap_launch --plugins

Runs the components of a launch file (launch_yaml/README.md describes the format).
  FILE             every group runs as its own child process, output prefixed with [group],
                   restarted when it dies (below); a single-group file runs in this process
  --group NAME     run only this group, in this process (one host's share of a deployment)
  --set C.P=V      set parameter P of component C to V (YAML: 3, 0.5, true, [1, 2], text)
  --duration S     stop after S seconds (default, or 0: run until Ctrl-C)
  --health-file P  rewrite P every second while callbacks run (several groups: P.GROUP each);
                   a container's HEALTHCHECK reads its age (default: $MOCAP_HEALTH_FILE)
  --check          validate the file and exit: 0 when valid
  --describe NAME  print a plugin's description, parameters and topics
  --plugins        list the plugins on the search path (MOCAP_PLUGIN_PATH, then
                   lib/mocap_graph/plugins beside bin/)
Environment: MOCAP_DOMAIN_ID overrides the DDS domain, MOCAP_LOG_LEVEL=debug|info|warn|error.

A group whose process dies after it has started (a signal, a non-zero exit) is started again
after 0.25 s, the wait doubling with each death within 60 s, for what is left of --duration;
the others go on. Its launch-file keys change that: `respawn: false` leaves it down,
`required: true` ends the deployment. One that dies 5 times within 60 s is given up on. A
group that exits with code 0 ends the deployment, as does one that fails while starting.
Restarts and give-ups are logged and published on /alerts (mocap_msgs/Alert) by this process's
DDS participant "launch"; a restarted group's /diagnostics say how many times it was restarted.
Every group gets a `diagnostics` component (its statuses on /diagnostics once a second, its
clock for the fusion's clock check) unless the file gives it one.
Exit code: 0, or that of the first group that failed for good (128 + N for signal N): it
failed to start, a required group died, or one was given up on or not restarted.
)";

[[noreturn]] void usage_error(std::string_view message) {
  fmt::print(stderr, "mocap_launch: {}\n\n{}", message, kUsage);
  std::exit(2);
}

std::string describe(const mocap::LoadedPlugin& plugin) {
  const mocap::ComponentSpec& spec = plugin.spec;
  std::string out =
      fmt::format("{}: {}\nlibrary: {}\n", plugin.name,
                  spec.description().empty() ? "(no description)" : spec.description(),
                  plugin.library.string());
  out += "\nparameters:\n";
  if (spec.parameters().empty()) out += "  (none)\n";
  for (const mocap::ParameterSpec& p : spec.parameters()) {
    out += fmt::format("  {}: {} = {}\n      {}\n", p.name, p.type_description(),
                       mocap::to_string(p.default_value), p.description);
  }
  out += "\ntopics:\n";
  if (spec.topics().empty()) out += "  (none)\n";
  for (const mocap::TopicSpec& t : spec.topics()) {
    out += fmt::format("  {} {} [{}] {}\n      {}\n",
                       t.direction == mocap::TopicDirection::Publish ? "publishes " : "subscribes",
                       t.topic, t.type ? t.type->name() : "any type",
                       t.type ? t.qos.to_string() : "QoS chosen at run time", t.description);
  }
  return out;
}

// Every group publishes its statuses on /diagnostics and answers clock probes (the
// diagnostics plugin), unless the file gives it one of its own.
void add_diagnostics(mocap::ComponentHost& host, const mocap::LaunchGroup& group,
                     mocap::PluginLoader& plugins) {
  for (const mocap::LaunchComponent& component : group.components) {
    if (component.plugin->name == kDiagnosticsPlugin) return;
  }
  host.add(*plugins.load(kDiagnosticsPlugin).factory, {.name = kDiagnosticsPlugin});
}

int run_group(const mocap::LaunchFile& file, const mocap::LaunchGroup& group,
              mocap::PluginLoader& plugins, std::optional<double> duration,
              const std::string& health_file, mocap::SupervisorReadyNotice& ready) {
  try {
    mocap::ComponentHost host(
        {group.name, group.threads, file.dds_of(group), mocap::known_topics(file), health_file});
    for (const mocap::LaunchComponent& component : group.components) {
      try {
        host.add(*component.plugin->factory, component.config);
      } catch (const mocap::ComponentError& e) {
        fmt::print(stderr, "{}:{}: {}\n", file.path, component.line, e.what());
        return 1;
      }
    }
    add_diagnostics(host, group, plugins);
    host.start();
    ready.started();
    std::optional<std::chrono::duration<double>> run_for;
    if (duration) run_for = std::chrono::duration<double>(*duration);
    return host.run(run_for);
  } catch (const std::exception& e) {
    fmt::print(stderr, "{}: group '{}': {}\n", file.path, group.name, e.what());
    return 1;
  }
}

// What the command line asks for.
struct Options {
  std::optional<std::string> file, group, describe_plugin;
  std::vector<std::string> set_texts;  // --set C.P=V, as given
  std::optional<double> duration;
  std::string health_file;
  bool check = false, list_plugins = false, help = false;
};

// Exits with a usage error for a bad command line.
Options parse_arguments(const std::vector<std::string>& args) {
  Options options;
  const char* health_file_variable = std::getenv("MOCAP_HEALTH_FILE");
  options.health_file = health_file_variable ? health_file_variable : "";
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    auto value = [&](std::string_view option) -> const std::string& {
      if (i + 1 >= args.size()) usage_error(fmt::format("{} needs a value", option));
      return args[++i];
    };
    if (arg == "--help" || arg == "-h") {
      options.help = true;
      return options;
    } else if (arg == "--group") {
      options.group = value(arg);
    } else if (arg == "--set") {
      options.set_texts.push_back(value(arg));
    } else if (arg == "--duration") {
      const std::string& text = value(arg);
      double seconds = 0;
      auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), seconds);
      if (error != std::errc() || end != text.data() + text.size() || !(seconds >= 0)) {
        usage_error(fmt::format("--duration {}: expected a number of seconds >= 0", text));
      }
      // The last one given counts, so a wrapper's default can be overridden; 0 means none.
      options.duration = seconds > 0 ? std::optional<double>(seconds) : std::nullopt;
    } else if (arg == "--health-file") {
      options.health_file = value(arg);
    } else if (arg == "--check") {
      options.check = true;
    } else if (arg == "--describe") {
      options.describe_plugin = value(arg);
    } else if (arg == "--plugins") {
      options.list_plugins = true;
    } else if (arg.starts_with("-")) {
      usage_error(fmt::format("unknown option {}", arg));
    } else if (options.file) {
      usage_error(fmt::format("one launch file at a time ({} and {})", *options.file, arg));
    } else {
      options.file = arg;
    }
  }
  return options;
}

void list_plugins(mocap::PluginLoader& plugins) {
  for (const std::string& name : plugins.available()) {
    try {
      const mocap::LoadedPlugin& plugin = plugins.load(name);
      fmt::print("{:28} {}\n", name, plugin.spec.description());
    } catch (const mocap::PluginError& e) {
      fmt::print("{:28} (cannot load: {})\n", name, e.what());
    }
  }
}

// One child process per group, each running this program with --group, supervised.
int run_groups(const mocap::LaunchFile& launch, const Options& options) {
  std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  std::vector<mocap::ChildProcess> children;
  for (const mocap::LaunchGroup& g : launch.groups) {
    mocap::ChildProcess child{
        g.name, {self, *options.file, "--group", g.name}, g.respawn, g.required};
    for (const std::string& text : options.set_texts) {
      child.argv.push_back("--set");
      child.argv.push_back(text);
    }
    if (!options.health_file.empty()) {
      child.argv.push_back("--health-file");
      child.argv.push_back(options.health_file + "." + g.name);
    }
    children.push_back(std::move(child));
  }
  mocap::SupervisionOptions supervision;
  if (options.duration) {
    supervision.duration = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(*options.duration));
  }
  std::unique_ptr<mocap::LaunchAlerts> alerts;
  if (launch.dds.enabled) {
    try {
      alerts = std::make_unique<mocap::LaunchAlerts>(launch.dds);
      supervision.on_event = [&alerts](const mocap::SupervisorEvent& event) {
        alerts->publish(event);
      };
    } catch (const std::exception& e) {
      fmt::print(stderr, "[launch] restarts will not be published on /alerts: {}\n", e.what());
    }
  }
  return mocap::supervise(children, supervision);
}

}  // namespace

int main(int argc, char** argv) {
  // Before anything else runs: the variable is not for the programs this one starts.
  mocap::SupervisorReadyNotice ready;
  const Options options = parse_arguments({argv + 1, argv + argc});
  if (options.help) {
    fmt::print("{}", kUsage);
    return 0;
  }
  mocap::PluginLoader plugins;
  if (options.list_plugins) {
    list_plugins(plugins);
    return 0;
  }
  if (options.describe_plugin) {
    try {
      fmt::print("{}", describe(plugins.load(*options.describe_plugin)));
      return 0;
    } catch (const mocap::PluginError& e) {
      fmt::print(stderr, "mocap_launch: {}\n", e.what());
      return 1;
    }
  }
  if (!options.file) usage_error("no launch file given");

  mocap::LaunchFile launch;
  try {
    std::vector<mocap::ParameterOverride> overrides;
    for (const std::string& text : options.set_texts) {
      overrides.push_back(mocap::parse_parameter_override(text));
    }
    launch = mocap::load_launch_file(*options.file, plugins, overrides);
  } catch (const mocap::LaunchError& e) {
    for (const std::string& problem : e.problems()) fmt::print(stderr, "{}\n", problem);
    fmt::print(stderr, "{}: {} problem(s); nothing was started\n", *options.file,
               e.problems().size());
    return 1;
  }
  const mocap::LaunchGroup* group = nullptr;
  if (options.group && (group = launch.find_group(*options.group)) == nullptr) {
    std::vector<std::string> names;
    for (const auto& g : launch.groups) names.push_back(g.name);
    fmt::print(stderr, "{}: no group named '{}' (groups: {})\n", launch.path, *options.group,
               fmt::join(names, ", "));
    return 1;
  }
  if (options.check) {
    fmt::print("{}: valid ({} group(s), {} component(s))\n", launch.path, launch.groups.size(),
               launch.component_count());
    return 0;
  }
  // One instant every process of this launch shares, its groups restarted ones too (they
  // inherit it): simulated cameras in different processes count scene time from it. A
  // launcher started with it set (one per host) keeps the value given.
  setenv(mocap::kLaunchStartVariable,
         std::to_string(std::chrono::duration_cast<std::chrono::nanoseconds>(
                            std::chrono::system_clock::now().time_since_epoch())
                            .count())
             .c_str(),
         0);
  if (!group && launch.groups.size() == 1) group = &launch.groups.front();
  if (group) {
    return run_group(launch, *group, plugins, options.duration, options.health_file, ready);
  }
  return run_groups(launch, options);
}
