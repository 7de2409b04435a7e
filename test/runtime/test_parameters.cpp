// Parameter values: YAML typing, declared types and ranges, typed reads.
#include <gtest/gtest.h>

#include <cmath>

#include <mocap/component_spec.hpp>
#include <mocap/parameter.hpp>
#include <mocap/parameter_list.hpp>

#include "launch/yaml_value.hpp"

namespace mocap {
namespace {

ParameterValue yaml(const std::string& text) { return parameter_value_from_yaml(YAML::Load(text)); }

TEST(YamlValues, PlainScalarsFollowTheCoreSchema) {
  EXPECT_EQ(yaml("true"), ParameterValue(true));
  EXPECT_EQ(yaml("False"), ParameterValue(false));
  EXPECT_EQ(yaml("42"), ParameterValue(int64_t{42}));
  EXPECT_EQ(yaml("-7"), ParameterValue(int64_t{-7}));
  EXPECT_EQ(yaml("0x1F"), ParameterValue(int64_t{31}));
  EXPECT_EQ(yaml("0.75"), ParameterValue(0.75));
  EXPECT_EQ(yaml("1e-3"), ParameterValue(0.001));
  EXPECT_EQ(yaml("-.inf"), ParameterValue(-INFINITY));
  EXPECT_TRUE(std::isnan(std::get<double>(yaml(".nan"))));
  EXPECT_EQ(yaml("camera_left"), ParameterValue(std::string("camera_left")));
  EXPECT_EQ(yaml("yes"), ParameterValue(std::string("yes")));  // YAML 1.2: not a bool
}

TEST(YamlValues, QuotedScalarsAreStrings) {
  EXPECT_EQ(yaml("\"42\""), ParameterValue(std::string("42")));
  EXPECT_EQ(yaml("'true'"), ParameterValue(std::string("true")));
}

TEST(YamlValues, ListsTakeTheirElementsType) {
  EXPECT_EQ(yaml("[1, 2, 3]"), ParameterValue(std::vector<int64_t>{1, 2, 3}));
  EXPECT_EQ(yaml("[1, 2.5]"), ParameterValue(std::vector<double>{1.0, 2.5}));
  EXPECT_EQ(yaml("[a, b]"), ParameterValue(std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(yaml("[]"), ParameterValue(std::vector<int64_t>{}));
}

TEST(YamlValues, WhatCannotBeAParameterIsRejected) {
  EXPECT_THROW(yaml("{a: 1}"), std::invalid_argument);
  EXPECT_THROW(yaml("[[1], [2]]"), std::invalid_argument);
  EXPECT_THROW(yaml("[1, a]"), std::invalid_argument);
  EXPECT_THROW(yaml("~"), std::invalid_argument);
  EXPECT_THROW(yaml("99999999999999999999"), std::invalid_argument);
}

ParameterSpec declared(ParameterValue default_value, std::optional<double> min = {},
                       std::optional<double> max = {}) {
  return {"p", std::move(default_value), "", min, max};
}

TEST(ParameterSpec, AcceptsItsTypeAndIntsForDoubles) {
  EXPECT_FALSE(declared(1.0).check(int64_t{3}));
  EXPECT_EQ(declared(1.0).coerce(int64_t{3}), ParameterValue(3.0));
  EXPECT_FALSE(declared(std::vector<double>{}).check(std::vector<int64_t>{1, 2}));
  EXPECT_EQ(declared(std::vector<double>{}).coerce(std::vector<int64_t>{1, 2}),
            ParameterValue(std::vector<double>{1.0, 2.0}));
  EXPECT_EQ(declared(std::vector<std::string>{"x"}).coerce(std::vector<int64_t>{}),
            ParameterValue(std::vector<std::string>{}));
}

TEST(ParameterSpec, RejectsOtherTypesWithAMessage) {
  auto why = declared(int64_t{1}).check(1.5);
  ASSERT_TRUE(why);
  EXPECT_EQ(*why, "expects int, got double 1.5");
  EXPECT_EQ(*declared(std::string("a")).check(int64_t{123}), "expects string, got int 123");
  EXPECT_EQ(*declared(true).check(std::string("yes")), "expects bool, got string \"yes\"");
  EXPECT_TRUE(declared(std::vector<int64_t>{}).check(int64_t{3}));
}

TEST(ParameterSpec, ChecksRangesOfNumbersAndListElements) {
  EXPECT_FALSE(declared(0.5, 0.0, 1.0).check(1.0));
  EXPECT_EQ(*declared(0.5, 0.0, 1.0).check(1.5), "expects double in [0, 1], got 1.5");
  EXPECT_TRUE(declared(0.5, 0.0, 1.0).check(NAN));
  EXPECT_FALSE(declared(0.5).check(NAN));
  EXPECT_EQ(*declared(int64_t{5}, 1).check(int64_t{0}), "expects int >= 1, got 0");
  EXPECT_EQ(*declared(std::vector<double>{}, 0.0).check(std::vector<double>{1, -2}),
            "expects list of double >= 0, got [1.0, -2.0] (element -2.0)");
}

TEST(Parameters, TypedReads) {
  Parameters p({{"b", true},
                {"i", int64_t{7}},
                {"d", 0.25},
                {"s", std::string("x")},
                {"il", std::vector<int64_t>{1, 2}},
                {"dl", std::vector<double>{0.5}},
                {"sl", std::vector<std::string>{"a"}}});
  EXPECT_TRUE(p.get<bool>("b"));
  EXPECT_EQ(p.get<int>("i"), 7);
  EXPECT_EQ(p.get<size_t>("i"), 7u);
  EXPECT_EQ(p.get<double>("d"), 0.25);
  EXPECT_EQ(p.get<std::string>("s"), "x");
  EXPECT_EQ(p.get<std::vector<int>>("il"), (std::vector<int>{1, 2}));
  EXPECT_EQ(p.get<std::vector<double>>("dl"), std::vector<double>{0.5});
  EXPECT_EQ(p.get<std::vector<std::string>>("sl"), std::vector<std::string>{"a"});
}

TEST(Parameters, ReadingUndeclaredOrAsAnotherTypeIsABug) {
  Parameters p({{"d", 0.25}});
  EXPECT_THROW(p.get<double>("missing"), std::logic_error);
  try {
    p.get<int>("d");
    FAIL();
  } catch (const std::logic_error& e) {
    EXPECT_STREQ(e.what(), "parameter 'd' is double, read as an integer type");
  }
}

// Settings as a component's: an algorithm's options as the base, a part several components
// share, and the component's own fields.
struct Lens {
  double ratio = 0.5;
  unsigned count = 3;
};
struct Files {
  std::string file = "a.yaml";
};
struct Settings : Lens {
  Lens second{.ratio = 0.25, .count = 7};  // initialized here: these are its defaults
  Files files;
  std::vector<int> ids = {1, 2};
  float gain = 1.5F;
  bool on = true;
};

const ParameterList<Files> kFiles =
    ParameterList<Files>().add("file", "a file", &Files::file).path();
const ParameterList<Settings> kSettings =
    ParameterList<Settings>()
        .add("ratio", "a ratio", &Settings::ratio)
        .range(0, 1)
        .add("count", "a count", &Settings::count)
        .add("second_ratio", "another ratio", &Settings::second, &Lens::ratio)
        .add("second_count", "another count", &Settings::second, &Lens::count)
        .max(100)
        .include(&Settings::files, kFiles)
        .add("ids", "servo ids", &Settings::ids)
        .add("gain", "a gain", &Settings::gain)
        .add("on", "a switch", &Settings::on);

TEST(ParameterList, DeclaresTheSettingsInitialValuesAsDefaults) {
  ComponentSpec spec;
  kSettings.declare(spec);
  std::vector<std::string> names;
  for (const ParameterSpec& p : spec.parameters()) names.push_back(p.name);
  EXPECT_EQ(names, (std::vector<std::string>{"ratio", "count", "second_ratio", "second_count",
                                             "file", "ids", "gain", "on"}));
  auto declared = [&](const char* name) { return *spec.find_parameter(name); };
  EXPECT_EQ(declared("ratio").default_value, ParameterValue(0.5));
  EXPECT_EQ(declared("ratio").type_description(), "double in [0, 1]");
  // Unsigned members take no negative values.
  EXPECT_EQ(declared("count").default_value, ParameterValue(int64_t{3}));
  EXPECT_EQ(declared("count").type_description(), "int >= 0");
  // A member of a member, and its default as the outer struct initializes it.
  EXPECT_EQ(declared("second_ratio").default_value, ParameterValue(0.25));
  EXPECT_EQ(declared("second_count").default_value, ParameterValue(int64_t{7}));
  EXPECT_EQ(declared("second_count").type_description(), "int in [0, 100]");
  EXPECT_EQ(declared("file").default_value, ParameterValue(std::string("a.yaml")));
  EXPECT_TRUE(declared("file").is_path);
  EXPECT_EQ(declared("ids").default_value, ParameterValue(std::vector<int64_t>{1, 2}));
  EXPECT_EQ(declared("gain").default_value, ParameterValue(1.5));
  EXPECT_EQ(declared("on").default_value, ParameterValue(true));
}

TEST(ParameterList, ReadsValuesIntoTheMembersTheyAreBoundTo) {
  ComponentSpec spec;
  kSettings.declare(spec);
  std::map<std::string, ParameterValue, std::less<>> values;
  for (const ParameterSpec& p : spec.parameters()) values[p.name] = p.default_value;
  // The defaults read back as the struct's own initial values.
  const Settings defaults = kSettings.read(Parameters(values));
  EXPECT_EQ(defaults.second.count, 7u);
  EXPECT_EQ(defaults.files.file, "a.yaml");

  values["ratio"] = 0.75;
  values["count"] = int64_t{9};
  values["second_ratio"] = 0.125;
  values["file"] = std::string("/b.yaml");
  values["ids"] = std::vector<int64_t>{4};
  values["gain"] = 2.5;
  values["on"] = false;
  const Settings read = kSettings.read(Parameters(values));
  EXPECT_EQ(read.ratio, 0.75);
  EXPECT_EQ(read.count, 9u);
  EXPECT_EQ(read.second.ratio, 0.125);
  EXPECT_EQ(read.second.count, 7u);
  EXPECT_EQ(read.files.file, "/b.yaml");
  EXPECT_EQ(read.ids, std::vector<int>{4});
  EXPECT_EQ(read.gain, 2.5F);
  EXPECT_FALSE(read.on);
}

TEST(ParameterList, DeclarationErrorsAreTheComponentsBugs) {
  struct Two {
    int a = 1;
    int b = 2;
  };
  ComponentSpec spec;
  EXPECT_THROW(ParameterList<Two>().add("a", "", &Two::a).add("a", "again", &Two::b).declare(spec),
               std::logic_error);
  ComponentSpec other;
  EXPECT_THROW(ParameterList<Two>().add("a", "", &Two::a).path().declare(other), std::logic_error);
  EXPECT_EQ(to_string(ParameterValue(std::vector<std::string>{"a", "b\""})), "[\"a\", \"b\\\"\"]");
}

}  // namespace
}  // namespace mocap
