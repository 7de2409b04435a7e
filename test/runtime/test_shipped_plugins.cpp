// The shipped plugins' declarations, as mocap_launch --describe shows them.
#include <gtest/gtest.h>

#include <mocap/component_host.hpp>

#include "core/plugin_loader.hpp"
#include "test_support.hpp"

namespace mocap {
namespace {

// Every shipped plugin, as --describe shows it: each parameter's default (ParameterList takes it
// from the initial value of the settings member the value is read into) passes the parameter's
// own checks, so a component started with nothing set gets what --describe promises, and a
// launch file that sets nothing is valid.
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
    }
    EXPECT_TRUE(check_component_config(plugin.spec, {.name = name}).empty()) << name;
  }
  EXPECT_GT(parameters, 150u);
}

}  // namespace
}  // namespace mocap
