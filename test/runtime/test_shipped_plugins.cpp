// The shipped plugins' declarations, as mocap_launch --describe shows them.
#include <gtest/gtest.h>

#include <mocap/component_host.hpp>

#include "core/plugin_loader.hpp"
#include "launch/yaml_value.hpp"
#include "test_support.hpp"

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

}  // namespace
}  // namespace mocap
