// What names look like, and help when one is misspelled.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <mocap/spelling.hpp>

namespace mocap {

// "/a/b_c": starts with '/', segments of letters, digits and '_'.
bool valid_topic_name(std::string_view topic);
// A topic family: a declared topic with `{name}` segments ("/pixart/{camera}/fiducials"),
// which a component instantiates at run time with values for them ("/pixart/cam0/fiducials").
bool is_topic_family(std::string_view topic);
// valid_topic_name, with `{name}` allowed as whole segments.
bool valid_topic_family(std::string_view family);
// The values of `family`'s placeholders that make `topic`, in order; nullopt if it does not
// match (each placeholder stands for exactly one segment).
std::optional<std::vector<std::string>> match_topic_family(std::string_view family,
                                                           std::string_view topic);
// `family` with its placeholders replaced, in order, by `values`.
std::string instantiate_topic_family(std::string_view family,
                                     const std::vector<std::string>& values);
// Whether two topics (each a topic or a family) can name the same topic: equal, or a family
// matching the other, or two families of the same shape.
bool topics_overlap(std::string_view a, std::string_view b);

// Component and group names: letters, digits, '_' and '-'.
bool valid_component_name(std::string_view name);

}  // namespace mocap
