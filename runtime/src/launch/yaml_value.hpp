// YAML values as parameter values, typed the way YAML 1.2's core schema reads them.
#pragma once

#include <yaml-cpp/yaml.h>

#include <mocap/parameter.hpp>

namespace mocap {

// A plain scalar is a bool (true/false), an int, a double (1.5, 1e-3, .inf) or else a
// string; a quoted scalar is always a string; a sequence of scalars is a list (ints and
// doubles together make a list of double). Throws std::invalid_argument for anything else
// (maps, nested lists, null, mixed lists), with a message saying what was found.
ParameterValue parameter_value_from_yaml(const YAML::Node& node);

}  // namespace mocap
