// The shipped plugins' declarations, as mocap_launch --describe shows them, and the shipped
// launch files that use them.
#include <gtest/gtest.h>

#include <filesystem>

#include <mocap/component_host.hpp>

#include "host/plugin_loader.hpp"
#include "launch/yaml_value.hpp"
#include "test/test_support.hpp"

namespace mocap {
namespace {

// Every shipped plugin, as --describe shows it: each parameter's default (ParameterList takes it
// from the initial value of the settings member the value is read into) passes the parameter's
// own checks, so a component started with nothing set gets what --describe promises, and a
// launch file that sets nothing is valid; and the default as --describe prints it reads back, in
// a launch file, as the same value (no digits lost, no int for a double).
TEST(ShippedPlugins, EveryDefaultPassesItsOwnChecks) {
  PluginLoader loader({test::plugin_dir()});
  const std::vector<std::string> names = loader.available();
  EXPECT_GE(names.size(), 24u);
  size_t parameters = 0;
  for (const std::string& name : names) {
    const LoadedPlugin& plugin = loader.load(name);
    for (const ParameterSpec& parameter : plugin.spec.parameters()) {
      ++parameters;
      EXPECT_EQ(parameter.check(parameter.default_value), std::nullopt)
          << name << "." << parameter.name;
      // --describe's text of the default, written into a launch file, is the default itself
      // once the host has read it (coerce: an int for a double, [] for any list).
      const std::string described = to_string(parameter.default_value);
      const ParameterValue read_back = parameter_value_from_yaml(YAML::Load(described));
      EXPECT_EQ(parameter.check(read_back), std::nullopt) << name << "." << parameter.name;
      EXPECT_EQ(parameter.coerce(read_back), parameter.default_value)
          << name << "." << parameter.name << " = " << described;
    }
    EXPECT_TRUE(check_component_config(plugin.spec, {.name = name}).empty()) << name;
  }
  EXPECT_GT(parameters, 150u);
}

// Every launch file shipped under launch_yaml/, found here rather than listed (a new one is
// checked the day it lands), is valid as `mocap_launch --check` reads it: plugins, parameters,
// topics and QoS, with the shipped plugins. The camera package's camera_source is built here as
// in the plain build, so follower_robot.yaml and mobile_mocap_camera.yaml are checked too.
TEST(ShippedLaunchFiles, EveryOneIsValid) {
  int checked = 0;
  for (const auto& entry :
       std::filesystem::recursive_directory_iterator(test::source_dir() / "launch_yaml")) {
    if (entry.path().extension() != ".yaml") continue;
    ++checked;
    auto [code, output] = test::run_command(
        {(test::bin_dir() / "mocap_launch").string(), entry.path().string(), "--check"});
    EXPECT_EQ(code, 0) << output;
    EXPECT_NE(output.find(": valid ("), std::string::npos) << output;
  }
  EXPECT_GE(checked, 14);
}

}  // namespace
}  // namespace mocap
