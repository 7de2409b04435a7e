// What a component declares before it exists: a description, parameters and topics.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <mocap/message_type.hpp>
#include <mocap/parameter.hpp>
#include <mocap/qos.hpp>

namespace mocap {

enum class TopicDirection { Publish, Subscribe };

// The topic of a declaration that covers every topic (publishes_any / subscribes_any).
inline constexpr std::string_view kAnyTopic = "*";

struct TopicSpec {
  std::string topic;                  // default name; launch files may remap it; or kAnyTopic
  const MessageType* type = nullptr;  // null for kAnyTopic: any type
  TopicDirection direction = TopicDirection::Publish;
  Qos qos;  // default; launch files may override it
  std::string description;
};

// The declaration lets the launcher validate a launch file, and `mocap_launch --describe`
// document a plugin, without constructing the component (which may open devices). Parameters
// come from the component's ParameterList (parameter_list.hpp), which binds each to a member
// of its settings struct:
//
//   static void declare(mocap::ComponentSpec& spec) {
//     spec.description("Finds bright round fiducials in mono8 images.");
//     kParameters.declare(spec);
//     spec.subscribes<sensor_msgs::msg::Image>("/camera/ir/image_raw", mocap::Qos::sensor_data(),
//                                              "camera images, mono8");
//     spec.publishes<mocap_msgs::msg::FiducialArray>("/mocap/fiducials", mocap::Qos::reliable(),
//                                                    "one array per image");
//   }
class ComponentSpec {
 public:
  void description(std::string text) { description_ = std::move(text); }

  // Adds a parameter (ParameterList::declare calls it). Throws std::logic_error for a name
  // declared twice, or a path that is not a string.
  void parameter(ParameterSpec declared);

  template <class Message>
  void publishes(std::string topic, Qos qos, std::string description) {
    add_topic({std::move(topic), &message_type<Message>(), TopicDirection::Publish, qos,
               std::move(description)});
  }
  template <class Message>
  void subscribes(std::string topic, Qos qos, std::string description) {
    add_topic({std::move(topic), &message_type<Message>(), TopicDirection::Subscribe, qos,
               std::move(description)});
  }

  // Topics chosen at run time, of any type (a recorder, a player). The component then uses
  // Context::advertise_any / subscribe_any with the type and QoS it picks. A launch file may
  // remap or set the QoS of any topic name for it; the one-type-per-topic rule is checked when
  // the topic is used, not when the launch file is read.
  void publishes_any(std::string description) {
    add_topic(
        {std::string(kAnyTopic), nullptr, TopicDirection::Publish, Qos{}, std::move(description)});
  }
  void subscribes_any(std::string description) {
    add_topic({std::string(kAnyTopic), nullptr, TopicDirection::Subscribe, Qos{},
               std::move(description)});
  }
  // The any-topic declaration in `direction`, or null.
  const TopicSpec* find_any_topic(TopicDirection direction) const;

  const std::string& description() const { return description_; }
  const std::vector<ParameterSpec>& parameters() const { return parameters_; }
  const std::vector<TopicSpec>& topics() const { return topics_; }
  const ParameterSpec* find_parameter(std::string_view name) const;
  const TopicSpec* find_topic(std::string_view topic) const;

 private:
  void add_topic(TopicSpec topic);

  std::string description_;
  std::vector<ParameterSpec> parameters_;
  std::vector<TopicSpec> topics_;
};

}  // namespace mocap
