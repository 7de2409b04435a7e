// Plugin loading: found by name on a search path or by path; every failure says which
// library, which symbol, and which plugins there are.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cstdlib>

#include "host/plugin_loader.hpp"
#include "test/test_support.hpp"

namespace mocap {
namespace {

class PluginLoaderTest : public ::testing::Test {
 protected:
  PluginLoader loader{{test::test_plugin_dir()}};

  std::string error_of(std::string_view plugin) {
    try {
      loader.load(plugin);
    } catch (const PluginError& e) {
      std::string message = e.what();
      EXPECT_EQ(message.find('\n'), std::string::npos);
      return message;
    }
    ADD_FAILURE() << plugin << " loaded";
    return "";
  }
  std::string library(std::string_view name) {
    return (test::test_plugin_dir() / ("libmocap_plugin_" + std::string(name) + ".so")).string();
  }
};

TEST_F(PluginLoaderTest, LoadsByNameWithItsDeclaration) {
  const LoadedPlugin& plugin = loader.load("sequence_sink");
  EXPECT_EQ(plugin.name, "sequence_sink");
  EXPECT_EQ(plugin.library, library("sequence_sink"));
  ASSERT_NE(plugin.spec.find_parameter("expect"), nullptr);
  ASSERT_NE(plugin.spec.find_topic("/test/sequence"), nullptr);
  EXPECT_EQ(&loader.load("sequence_sink"), &plugin);  // loaded once
}

TEST_F(PluginLoaderTest, LoadsByPath) {
  EXPECT_EQ(loader.load(library("sequence_source")).name, "sequence_source");
  EXPECT_EQ(error_of("/nowhere/libmocap_plugin_x.so"),
            "plugin library /nowhere/libmocap_plugin_x.so does not exist");
}

TEST_F(PluginLoaderTest, ListsAvailablePlugins) {
  auto available = loader.available();
  EXPECT_NE(std::find(available.begin(), available.end(), "sequence_source"), available.end());
  EXPECT_NE(std::find(available.begin(), available.end(), "not_a_plugin"), available.end());
}

TEST_F(PluginLoaderTest, UnknownName) {
  std::string message = error_of("camera");
  EXPECT_EQ(message.rfind("plugin 'camera' not found: no libmocap_plugin_camera.so in " +
                              test::test_plugin_dir().string() + " (available plugins: ",
                          0),
            0u)
      << message;
  EXPECT_NE(message.find("sequence_sink"), std::string::npos);
}

TEST_F(PluginLoaderTest, LibraryWithoutTheSymbol) {
  EXPECT_EQ(error_of("not_a_plugin"),
            library("not_a_plugin") +
                " is not a mocap-graph plugin: it does not export the symbol "
                "'mocap_component_factory' (register the component with "
                "MOCAP_REGISTER_COMPONENT)");
}

TEST_F(PluginLoaderTest, LibraryThatCannotLoad) {
  std::string message = error_of("unresolved");
  EXPECT_EQ(message.rfind("cannot load plugin library " + library("unresolved") + ": ", 0), 0u)
      << message;
  EXPECT_NE(message.find("undefined symbol: function_that_exists_nowhere"), std::string::npos)
      << message;
}

TEST_F(PluginLoaderTest, OtherAbi) {
  EXPECT_EQ(error_of("wrong_abi"),
            library("wrong_abi") +
                fmt::format(" was built for component ABI 0, this runtime has ABI {}; rebuild the "
                            "plugin",
                            ComponentFactory::kAbiVersion));
}

TEST_F(PluginLoaderTest, LibraryRegisteringAnotherName) {
  EXPECT_EQ(error_of("misnamed"),
            library("misnamed") + " registers plugin 'another_name', not 'misnamed'");
}

TEST_F(PluginLoaderTest, InvalidDeclaration) {
  EXPECT_EQ(error_of("bad_declaration"),
            "plugin 'bad_declaration' (" + library("bad_declaration") +
                ") has an invalid declaration: parameter 'twice' is declared twice");
}

TEST(PluginSearchPath, EnvironmentFirstThenNextToTheExecutable) {
  setenv("MOCAP_PLUGIN_PATH", "/a:/b::/c", 1);
  auto path = PluginLoader::default_search_path();
  unsetenv("MOCAP_PLUGIN_PATH");
  ASSERT_EQ(path.size(), 4u);
  EXPECT_EQ(path[0], "/a");
  EXPECT_EQ(path[2], "/c");
  EXPECT_EQ(path[3], test::plugin_dir());
}

}  // namespace
}  // namespace mocap
