// Launch files: everything wrong is found before anything starts, one line per problem,
// naming the file, the line and the key.
#include <gtest/gtest.h>

#include "dds/dds_transport.hpp"
#include "host/dds_implementations.hpp"
#include "launch/launch_file.hpp"
#include "test/test_support.hpp"

namespace mocap {
namespace {

class LaunchFileTest : public ::testing::Test {
 protected:
  PluginLoader plugins{{test::plugin_dir(), test::test_plugin_dir()}};
  test::TempDir dir;

  LaunchFile load(const std::string& yaml, const std::vector<std::string>& sets = {}) {
    test::write_file(dir / "launch.yaml", yaml);
    std::vector<ParameterOverride> overrides;
    for (const std::string& s : sets) overrides.push_back(parse_parameter_override(s));
    return load_launch_file(dir / "launch.yaml", plugins, overrides);
  }

  // The problems reported for `yaml`, with the file's path shortened to "launch.yaml".
  std::vector<std::string> problems(const std::string& yaml,
                                    const std::vector<std::string>& sets = {}) {
    try {
      load(yaml, sets);
    } catch (const LaunchError& e) {
      std::vector<std::string> out;
      std::string path = (dir / "launch.yaml").string();
      for (std::string p : e.problems()) {
        EXPECT_EQ(p.find('\n'), std::string::npos) << "one line per problem: " << p;
        for (size_t at; (at = p.find(path)) != std::string::npos;)
          p.replace(at, path.size(), "launch.yaml");
        out.push_back(p);
      }
      return out;
    }
    ADD_FAILURE() << "no problem found in:\n" << yaml;
    return {};
  }

  std::string only_problem(const std::string& yaml, const std::vector<std::string>& sets = {}) {
    auto list = problems(yaml, sets);
    EXPECT_EQ(list.size(), 1u) << ::testing::PrintToString(list);
    return list.empty() ? "" : list.front();
  }
};

constexpr const char* kValid = R"(dds:
  domain_id: 7
  shared_memory: false
groups:
  - name: source
    threads: 2
    components:
      - plugin: sequence_source
        name: source
        parameters: {count: 20, period_s: 1}
        qos: {/test/sequence: {profile: reliable, depth: 50, max_blocking_s: 0.25}}
  - name: sink
    components:
      - plugin: sequence_sink
        name: sink
        parameters:
          expect: 20
        remap: {/test/sequence: /other}
)";

TEST_F(LaunchFileTest, ReadsAValidFile) {
  LaunchFile file = load(kValid);
  EXPECT_EQ(file.dds.domain_id, 7);
  EXPECT_FALSE(file.dds.shared_memory);
  ASSERT_EQ(file.groups.size(), 2u);
  EXPECT_EQ(file.groups[0].name, "source");
  EXPECT_EQ(file.groups[0].threads, 2);
  const LaunchComponent& source = file.groups[0].components.at(0);
  EXPECT_EQ(source.plugin->name, "sequence_source");
  EXPECT_EQ(source.config.parameters.at("count"), ParameterValue(int64_t{20}));
  EXPECT_EQ(source.config.qos.at("/test/sequence").depth, 50);
  EXPECT_EQ(source.config.qos.at("/test/sequence").max_blocking, std::chrono::milliseconds(250));
  EXPECT_EQ(source.config.qos.at("/test/sequence").to_string(),
            "reliable, volatile, keep_all 50, max_blocking 250 ms");
  EXPECT_EQ(source.line, 9);
  EXPECT_EQ(file.groups[1].components.at(0).config.remaps.at("/test/sequence"), "/other");
  EXPECT_EQ(file.component_count(), 2u);
}

TEST_F(LaunchFileTest, SetOverridesAParameter) {
  LaunchFile file = load(kValid, {"sink.expect=5", "source.period_s=0.5"});
  EXPECT_EQ(file.groups[1].components[0].config.parameters.at("expect"),
            ParameterValue(int64_t{5}));
  EXPECT_EQ(file.groups[0].components[0].config.parameters.at("period_s"), ParameterValue(0.5));
}

TEST_F(LaunchFileTest, YamlSyntax) {
  EXPECT_EQ(only_problem("groups:\n  - name: a\n    components: [\n"),
            "launch.yaml:4:1: YAML error: end of sequence flow not found");
}

TEST_F(LaunchFileTest, OddValuesAreProblemsNotCrashes) {
  auto list = problems(R"(groups:
  - name: g
    components:
      - plugin: sequence_source
        name: source
        parameters: {period_s: 1e400, [count]: 3}
        remap: {[a]: /b}
)");
  ASSERT_EQ(list.size(), 3u) << ::testing::PrintToString(list);
  EXPECT_EQ(list[0], "launch.yaml:6: a key in 'parameters' is not a name");
  EXPECT_EQ(list[1],
            "launch.yaml:6: component 'source': parameter 'period_s' has number 1e400 is "
            "out of range");
  EXPECT_EQ(list[2], "launch.yaml:7: a key in 'remap' is not a name");
}

TEST_F(LaunchFileTest, MissingFile) {
  try {
    load_launch_file(dir / "nowhere.yaml", plugins);
    FAIL();
  } catch (const LaunchError& e) {
    EXPECT_NE(e.problems().at(0).find("nowhere.yaml: cannot read the launch file"),
              std::string::npos);
  }
}

TEST_F(LaunchFileTest, Structure) {
  EXPECT_EQ(only_problem("- a\n"),
            "launch.yaml:1: a launch file is a map with 'groups' (and optionally 'dds')");
  EXPECT_EQ(only_problem("dds: {}\n"),
            "launch.yaml:1: 'groups' must be a non-empty list of groups");
  EXPECT_EQ(only_problem("groups: []\n"),
            "launch.yaml:1: 'groups' must be a non-empty list of groups");
  EXPECT_EQ(only_problem("groups:\n  - name: g\n"),
            "launch.yaml:2: group 'g' needs 'components', a non-empty list");
  EXPECT_EQ(only_problem("groups:\n  - name: g\n    components:\n      - name: x\n"),
            "launch.yaml:4: a component needs a 'plugin'");
  EXPECT_EQ(only_problem("groups:\n  - name: g\n    components:\n      - plugin: sequence_sink\n"),
            "launch.yaml:4: a component needs a 'name'");
}

TEST_F(LaunchFileTest, UnknownKeysAtEveryLevel) {
  auto list = problems(R"(dds: {domain: 3}
groups:
  - name: g
    thread: 2
    components:
      - plugin: sequence_sink
        name: s
        paramters: {expect: 1}
extra: 1
)");
  ASSERT_EQ(list.size(), 4u);
  EXPECT_EQ(list[0], "launch.yaml:1: unknown key 'domain' in 'dds' (did you mean 'domain_id'?)");
  EXPECT_EQ(list[1], "launch.yaml:4: unknown key 'thread' in a group (did you mean 'threads'?)");
  EXPECT_EQ(list[2],
            "launch.yaml:8: unknown key 'paramters' in a component (did you mean 'parameters'?)");
  EXPECT_EQ(list[3], "launch.yaml:9: unknown key 'extra' in the launch file (keys: dds, groups)");
}

TEST_F(LaunchFileTest, UnknownPlugin) {
  std::string problem = only_problem(
      "groups:\n  - name: g\n    components:\n      - plugin: sequence_snk\n        name: s\n");
  EXPECT_EQ(problem.rfind("launch.yaml:4: plugin 'sequence_snk' not found: no "
                          "libmocap_plugin_sequence_snk.so in ",
                          0),
            0u)
      << problem;
  EXPECT_NE(problem.find("(did you mean 'sequence_sink'?)"), std::string::npos) << problem;
}

TEST_F(LaunchFileTest, ParameterNamesTypesAndRanges) {
  auto list = problems(R"(groups:
  - name: g
    components:
      - plugin: sequence_source
        name: source
        parameters:
          count: many
          period_s: -1
          batch: 2.5
          colour: red
          subscribers: "1"
)");
  ASSERT_EQ(list.size(), 5u);
  EXPECT_EQ(list[0],
            "launch.yaml:7: component 'source' (sequence_source): parameter 'count' "
            "expects int >= 0, got string \"many\"");
  EXPECT_EQ(list[1],
            "launch.yaml:8: component 'source' (sequence_source): parameter 'period_s' "
            "expects double in [1e-05, 60], got -1");
  EXPECT_EQ(list[2],
            "launch.yaml:9: component 'source' (sequence_source): parameter 'batch' "
            "expects int >= 1, got double 2.5");
  EXPECT_EQ(list[3],
            "launch.yaml:10: component 'source' (sequence_source): unknown parameter "
            "'colour' (parameters: count, batch, period_s, subscribers, summary_file, "
            "stop_when_done)");
  EXPECT_EQ(list[4],
            "launch.yaml:11: component 'source' (sequence_source): parameter "
            "'subscribers' expects int >= 0, got string \"1\"");
}

TEST_F(LaunchFileTest, DuplicateNamesAndKeys) {
  auto list = problems(R"(groups:
  - name: g
    components:
      - plugin: sequence_sink
        name: twin
        parameters: {expect: 1, expect: 2}
  - name: g
    components:
      - plugin: sequence_source
        name: twin
)");
  ASSERT_EQ(list.size(), 3u);
  EXPECT_EQ(list[0], "launch.yaml:6: 'expect' appears twice in 'parameters'");
  EXPECT_EQ(list[1], "launch.yaml:7: duplicate group name 'g' (first at line 2)");
  EXPECT_EQ(list[2], "launch.yaml:10: duplicate component name 'twin' (first at line 5)");
}

TEST_F(LaunchFileTest, TopicWithTwoTypes) {
  EXPECT_EQ(only_problem(R"(groups:
  - name: g
    components:
      - plugin: sequence_source
        name: numbers
      - plugin: image_sink
        name: images
)"),
            "launch.yaml:7: topic '/test/sequence' is sensor_msgs/msg/Image for component "
            "'images' but mocap_msgs/msg/FiducialArray for component 'numbers' (line 5)");
  // The same clash made by a remap, across groups.
  EXPECT_EQ(only_problem(R"(groups:
  - name: a
    components:
      - plugin: fiducial_pattern_source
        name: pattern
        remap: {/demo/fiducials: /images}
  - name: b
    components:
      - plugin: image_sink
        name: images
        remap: {/test/sequence: /images}
)"),
            "launch.yaml:10: topic '/images' is sensor_msgs/msg/Image for component 'images' but "
            "mocap_msgs/msg/FiducialArray for component 'pattern' (line 5)");
}

TEST_F(LaunchFileTest, QosThatCannotMatch) {
  EXPECT_EQ(only_problem(R"(groups:
  - name: g
    components:
      - plugin: fiducial_pattern_source
        name: pattern
      - plugin: sequence_sink
        name: sink
        remap: {/test/sequence: /demo/fiducials}
)"),
            "launch.yaml:7: topic '/demo/fiducials': component 'sink' (reliable) would receive "
            "nothing from component 'pattern' (line 5, sensor_data): the subscriber requests "
            "reliable delivery but the publisher offers best_effort");
}

TEST_F(LaunchFileTest, RemapsAndQos) {
  auto list = problems(R"(groups:
  - name: g
    components:
      - plugin: sequence_sink
        name: sink
        remap: {/test/sequense: /x, /test/sequence: not a topic}
        qos: {/test/sequence: fast, /nothing: reliable}
)");
  ASSERT_EQ(list.size(), 4u);
  EXPECT_EQ(list[0],
            "launch.yaml:6: component 'sink' (sequence_sink): remap target 'not a "
            "topic' is not a topic name (like /a/b_c)");
  EXPECT_EQ(list[1],
            "launch.yaml:6: component 'sink' (sequence_sink): remap of unknown topic "
            "'/test/sequense' (did you mean '/test/sequence'?)");
  EXPECT_EQ(list[2],
            "launch.yaml:7: QoS for '/test/sequence': unknown profile 'fast' (profiles: "
            "sensor_data, reliable, latched)");
  EXPECT_EQ(list[3],
            "launch.yaml:7: component 'sink' (sequence_sink): QoS for unknown topic "
            "'/nothing' (topics: /test/sequence)");
}

TEST_F(LaunchFileTest, MaxBlockingIsAReliablePublishersLimit) {
  auto list = problems(R"(groups:
  - name: g
    components:
      - plugin: sequence_source
        name: source
        qos: {/test/sequence: {profile: sensor_data, max_blocking_s: 0.1}}
      - plugin: sequence_source
        name: source2
        qos: {/test/sequence: {profile: reliable, max_blocking_s: forever}}
      - plugin: sequence_source
        name: source3
        qos: {/test/sequence: {profile: reliable, max_blocking_s: 0}}
      - plugin: sequence_sink
        name: sink
        qos: {/test/sequence: {profile: reliable, max_blocking_s: 1}}
)");
  ASSERT_EQ(list.size(), 4u) << ::testing::PrintToString(list);
  EXPECT_EQ(list[0],
            "launch.yaml:6: QoS for '/test/sequence': max_blocking_s applies to the reliable "
            "profile (keep_all), not to sensor_data");
  EXPECT_EQ(list[1],
            "launch.yaml:9: 'max_blocking_s' must be a number of seconds in [0.001, 3600]");
  EXPECT_EQ(list[2],
            "launch.yaml:12: 'max_blocking_s' must be a number of seconds in [0.001, 3600]");
  EXPECT_EQ(list[3],
            "launch.yaml:15: component 'sink' (sequence_sink): QoS for '/test/sequence': "
            "max_blocking_s limits a publisher's wait, and the component subscribes to this "
            "topic");
}

TEST_F(LaunchFileTest, DdsAndGroupSettings) {
  auto list = problems(R"(dds: {domain_id: 233, shared_memory: maybe, enabled: 1}
groups:
  - name: "bad name"
    threads: 0
    components:
      - plugin: sequence_sink
        name: "sink!"
)");
  ASSERT_EQ(list.size(), 6u);
  EXPECT_EQ(list[0], "launch.yaml:1: 'enabled' must be true or false");
  EXPECT_EQ(list[1], "launch.yaml:1: 'domain_id' must be an integer in [0, 232]");
  EXPECT_EQ(list[2], "launch.yaml:1: 'shared_memory' must be true or false");
  EXPECT_EQ(list[3], "launch.yaml:3: group name 'bad name' must use letters, digits, '_' and '-'");
  EXPECT_EQ(list[4], "launch.yaml:4: 'threads' must be an integer in [1, 256]");
  EXPECT_EQ(list[5], "launch.yaml:7: component name 'sink!' must use letters, digits, '_' and '-'");
}

// What the launcher does when a group's process dies: restarted unless the group says otherwise
// (group_supervisor.hpp).
TEST_F(LaunchFileTest, RespawnAndRequiredPerGroup) {
  LaunchFile file = load(R"(groups:
  - name: camera
    components: [{plugin: sequence_source, name: source}]
  - name: recorder
    respawn: false
    components: [{plugin: sequence_sink, name: sink}]
  - name: compute
    required: true
    components: [{plugin: sequence_sink, name: sink2}]
)");
  ASSERT_EQ(file.groups.size(), 3u);
  EXPECT_TRUE(file.groups[0].respawn);
  EXPECT_FALSE(file.groups[0].required);
  EXPECT_FALSE(file.groups[1].respawn);
  EXPECT_FALSE(file.groups[1].required);
  EXPECT_TRUE(file.groups[2].required);
  auto list = problems(R"(groups:
  - name: a
    respawn: sometimes
    components: [{plugin: sequence_source, name: source}]
  - name: b
    respawn: true
    required: true
    components: [{plugin: sequence_sink, name: sink}]
)");
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0], "launch.yaml:3: 'respawn' must be true or false");
  EXPECT_EQ(list[1],
            "launch.yaml:7: group 'b': 'required' ends the deployment when it dies, 'respawn' "
            "restarts it: choose one");
}

// The DDS implementation: the file's, a group's own (which wins), and MOCAP_DDS_IMPLEMENTATION
// when neither says; an unknown name, or what an implementation cannot do, is a problem at its
// line.
TEST_F(LaunchFileTest, DdsImplementationPerFileAndGroup) {
  LaunchFile file = load(R"(dds: {implementation: cyclonedds}
groups:
  - name: a
    components:
      - plugin: sequence_source
        name: source
  - name: b
    dds: {implementation: fastdds}
    components:
      - plugin: sequence_sink
        name: sink
)");
  EXPECT_EQ(file.dds_of(file.groups[0]).implementation, "cyclonedds");
  EXPECT_EQ(file.dds_of(file.groups[1]).implementation, "fastdds");

  EXPECT_EQ(only_problem(R"(dds: {implementation: zenoh}
groups:
  - name: a
    dds: {implementation: fastdds}
    components:
      - plugin: sequence_sink
        name: sink
)"),
            "launch.yaml:1: dds: implementation 'zenoh' is not a DDS implementation here "
            "(available: " +
                dds_implementation_names() + ")");
  auto list = problems(R"(groups:
  - name: a
    dds: {implementation: cyclone, domain_id: 3}
    components:
      - plugin: sequence_sink
        name: sink
)");
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0],
            "launch.yaml:3: unknown key 'domain_id' in a group's 'dds' (keys: implementation)");
  EXPECT_EQ(list[1],
            "launch.yaml:3: dds: implementation 'cyclone' is not a DDS implementation here "
            "(available: " +
                dds_implementation_names() + ")");

  // Discovery servers: not with a group on an implementation without them.
  EXPECT_EQ(only_problem(R"(dds:
  discovery: {server: "127.0.0.1:11811"}
groups:
  - name: a
    dds: {implementation: cyclonedds}
    components:
      - plugin: sequence_sink
        name: sink
)"),
            "launch.yaml:2: dds.discovery.server: cyclonedds has no discovery servers (group 'a', "
            "line 4); run that group on an implementation that has them (fastdds), or use "
            "multicast discovery (launch_yaml/README.md says how to give it its peers instead)");
}

TEST_F(LaunchFileTest, SetOptions) {
  EXPECT_THROW(parse_parameter_override("sink.expect"), LaunchError);
  EXPECT_THROW(parse_parameter_override("expect=3"), LaunchError);
  EXPECT_THROW(parse_parameter_override(".expect=3"), LaunchError);
  auto list = problems(kValid, {"nobody.expect=1", "sink.expect=[1", "sink.expect=lots"});
  ASSERT_EQ(list.size(), 3u);
  EXPECT_EQ(list[0], "--set nobody.expect=1: no component named 'nobody' in launch.yaml");
  EXPECT_EQ(list[1].rfind("--set sink.expect=[1: the value is not valid: ", 0), 0u) << list[1];
  EXPECT_EQ(list[2],
            "--set sink.expect=lots: component 'sink' (sequence_sink): parameter 'expect' "
            "expects int >= 0, got string \"lots\"");
}

}  // namespace
}  // namespace mocap
