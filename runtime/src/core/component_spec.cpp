#include <mocap/component_spec.hpp>

#include <stdexcept>

#include <fmt/format.h>

#include "core/names.hpp"

namespace mocap {

const ParameterSpec* ComponentSpec::find_parameter(std::string_view name) const {
  for (const ParameterSpec& p : parameters_) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

const TopicSpec* ComponentSpec::find_topic(std::string_view topic) const {
  for (const TopicSpec& t : topics_) {
    if (t.topic == topic) return &t;
  }
  return nullptr;
}

void ComponentSpec::parameter(ParameterSpec declared) {
  if (find_parameter(declared.name) != nullptr) {
    throw std::logic_error(fmt::format("parameter '{}' is declared twice", declared.name));
  }
  if (declared.is_path && declared.type() != ParameterType::String &&
      declared.type() != ParameterType::StringList) {
    throw std::logic_error(fmt::format(
        "parameter '{}': only a string or a list of strings can be a path", declared.name));
  }
  parameters_.push_back(std::move(declared));
}

const TopicSpec* ComponentSpec::find_any_topic(TopicDirection direction) const {
  for (const TopicSpec& t : topics_) {
    if (t.topic == kAnyTopic && t.direction == direction) return &t;
  }
  return nullptr;
}

void ComponentSpec::add_topic(TopicSpec topic) {
  if (topic.topic == kAnyTopic) {
    if (find_any_topic(topic.direction) != nullptr) {
      throw std::logic_error("any-topic declarations: one per direction");
    }
    topics_.push_back(std::move(topic));
    return;
  }
  if (find_topic(topic.topic) != nullptr) {
    throw std::logic_error(fmt::format("topic '{}' is declared twice", topic.topic));
  }
  if (!topic.topic.starts_with('/')) {
    throw std::logic_error(fmt::format("topic '{}' must start with '/'", topic.topic));
  }
  if (is_topic_family(topic.topic) && !valid_topic_family(topic.topic)) {
    throw std::logic_error(fmt::format(
        "topic family '{}': placeholders are whole segments like /a/{{name}}/b", topic.topic));
  }
  if (topic.qos.depth < 1) {
    throw std::logic_error(fmt::format("topic '{}' has QoS depth {}; it must be at least 1",
                                       topic.topic, topic.qos.depth));
  }
  topics_.push_back(std::move(topic));
}

}  // namespace mocap
