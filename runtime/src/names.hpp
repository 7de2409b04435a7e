// What names look like, and help when one is misspelled.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace mocap {

// "/a/b_c": starts with '/', segments of letters, digits and '_'.
bool valid_topic_name(std::string_view topic);
// Component and group names: letters, digits, '_' and '-'.
bool valid_component_name(std::string_view name);

// " (did you mean 'rate_hz'?)" when a candidate is close to `word`, otherwise the list of
// candidates: " (parameters: a, b)", or " (it has no parameters)".
std::string did_you_mean(std::string_view word, const std::vector<std::string>& candidates,
                         std::string_view what);

}  // namespace mocap
