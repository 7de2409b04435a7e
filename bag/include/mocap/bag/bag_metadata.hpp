// What a bag holds, as rosbag2 (ROS 2 Humble) describes it in a bag directory's metadata.yaml
// (version 5, storage_identifier sqlite3 or mcap), in the topics table of each .db3 file and
// in the channels of each .mcap file.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <mocap/qos.hpp>

namespace mocap::bag {

struct BagTopic {
  std::string name;  // "/camera/ir/image_raw"
  std::string type;  // ROS 2 type name: "sensor_msgs/msg/Image"
  std::string serialization_format = "cdr";
  // The QoS of each publisher the recorder saw, as rosbag2's offered_qos_profiles lists them.
  std::vector<Qos> offered_qos;
  uint64_t message_count = 0;
  // The type's definition as an MCAP Schema holds it: ROS 2's "ros2idl" layout (ros2idl_schema
  // in mocap/message_type.hpp). Empty: unknown (the schema is then left out). sqlite3 bags do
  // not keep it.
  std::string type_definition{};
};

struct BagFile {
  std::string path;  // relative to the bag directory: "run_0.db3"
  int64_t start_ns = 0, duration_ns = 0;
  uint64_t message_count = 0;
};

struct BagMetadata {
  std::string storage_identifier = "sqlite3";  // or "mcap"
  std::vector<BagFile> files;
  std::vector<BagTopic> topics;
  int64_t start_ns = 0;  // the earliest message's timestamp, nanoseconds since the epoch
  int64_t duration_ns = 0;
  uint64_t message_count = 0;
};

// metadata.yaml as rosbag2 Humble writes it (rosbag2_bagfile_information, version 5).
std::string format_metadata_yaml(const BagMetadata& metadata);
// Reads versions 4 to 9 (what Humble to Jazzy write); `source` names the file in errors.
// Throws BagError naming the file and key.
BagMetadata parse_metadata_yaml(const std::string& text, const std::string& source);

// The offered_qos_profiles string of a topic: a YAML list of rmw QoS profiles (history,
// depth, reliability, durability, deadline, lifespan, liveliness, lease duration,
// avoid_ros_namespace_conventions), rmw's enum numbers, "infinite" durations as rosbag2 spells
// them. History and depth as Qos has them: keep_last with its depth, keep_all with depth 0 (rmw
// has no depth for keep_all, so a keep-all Qos's depth reads back as Qos's default). Humble's
// recorder, which cannot see them, writes rmw's "unknown" there; that too reads as Qos's
// defaults.
std::string format_offered_qos_profiles(const std::vector<Qos>& offered);
// Lenient: unknown or missing values keep Qos's defaults; an unreadable string gives none.
std::vector<Qos> parse_offered_qos_profiles(const std::string& yaml);

// The QoS a player offers for a topic recorded with `offered`: reliable and transient local
// only if every recorded publisher was, so that every subscriber that matched one of them
// matches the player.
Qos playback_qos(const std::vector<Qos>& offered);

}  // namespace mocap::bag
