// What names look like, and help when one is misspelled.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <mocap/spelling.hpp>

namespace mocap {

// "/a/b_c": starts with '/', segments of letters, digits and '_'.
bool valid_topic_name(std::string_view topic);
// Component and group names: letters, digits, '_' and '-'.
bool valid_component_name(std::string_view name);

}  // namespace mocap
