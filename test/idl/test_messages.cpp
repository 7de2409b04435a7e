// The message contract: every IDL type has type support, serializes as XCDR1 exactly as
// fastddsgen's own Fast DDS type support does, and carries ROS 2 names on the wire.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <random>

#include <fastdds/rtps/common/SerializedPayload.h>

#include <mocap/generated_dds_type_supports.hpp>
#include <mocap/generated_message_types.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>
#include <sensor_msgs/msg/image.hpp>
#include <std_msgs/msg/header.hpp>

#include "dds/fastdds/fastdds_type_adapter.hpp"
#include "messages/cdr_format.hpp"
#include "messages/idl_schema.hpp"
#include "test/random_cdr.hpp"
#include "test/test_support.hpp"

namespace mocap {
namespace {

using eprosima::fastrtps::rtps::SerializedPayload_t;

std::vector<uint8_t> serialize(const MessageType& type, const void* message) {
  std::vector<uint8_t> bytes(type.serialized_size(message), 0);
  bytes.resize(type.serialize(message, bytes));
  return bytes;
}

TEST(Messages, EveryIdlFileHasTypeSupport) {
  std::set<std::string> from_files;
  for (const auto& entry :
       std::filesystem::recursive_directory_iterator(test::source_dir() / "idl")) {
    if (entry.path().extension() != ".idl") continue;
    auto relative = std::filesystem::relative(entry.path(), test::source_dir() / "idl");
    from_files.insert(relative.replace_extension().string());
  }
  std::set<std::string> generated;
  for (const MessageType* type : generated_message_types()) generated.insert(type->name());
  EXPECT_EQ(from_files, generated);
  EXPECT_GE(generated.size(), 23u);
  EXPECT_TRUE(generated.contains("mocap_msgs/msg/ConstellationPoseArray"));
}

TEST(Messages, RosNamesOnTheWire) {
  const MessageType& type = message_type<mocap_msgs::msg::FiducialArray>();
  EXPECT_EQ(type.name(), "mocap_msgs/msg/FiducialArray");
  EXPECT_EQ(type.dds_name(), "mocap_msgs::msg::dds_::FiducialArray_");
  EXPECT_EQ(find_message_type("sensor_msgs::msg::dds_::Image_"),
            &message_type<sensor_msgs::msg::Image>());
  EXPECT_EQ(find_message_type("sensor_msgs/msg/Image"), &message_type<sensor_msgs::msg::Image>());
  EXPECT_EQ(dds_topic_name("/camera/ir/image_raw"), "rt/camera/ir/image_raw");
  EXPECT_EQ(ros_topic_name("rt/camera/ir/image_raw"), "/camera/ir/image_raw");
  EXPECT_EQ(ros_type_name("geometry_msgs::msg::dds_::PoseStamped_"),
            "geometry_msgs/msg/PoseStamped");
  EXPECT_EQ(ros_type_name("SomeVendorType"), "SomeVendorType");
  EXPECT_EQ(DdsTypeAdapter(type).getName(), std::string("mocap_msgs::msg::dds_::FiducialArray_"));
}

// Bytes worked out by hand from the XCDR1 rules: 4-byte encapsulation (CDR, little endian),
// int32 sec, uint32 nanosec, string as uint32 length with terminating NUL.
TEST(Messages, HeaderHasTheXcdr1Layout) {
  std_msgs::msg::Header header;
  header.stamp().sec(1);
  header.stamp().nanosec(2);
  header.frame_id("ab");
  std::vector<uint8_t> expected = {0x00, 0x01, 0x00, 0x00, 1, 0, 0,   0,   2, 0,
                                   0,    0,    3,    0,    0, 0, 'a', 'b', 0};
  EXPECT_EQ(serialize(message_type<std_msgs::msg::Header>(), &header), expected);
}

// For every type: random valid CDR -> message -> CDR gives the same bytes, through our
// type support and through fastddsgen's, and both agree on the names.
TEST(Messages, EveryTypeRoundTripsAndMatchesFastddsgen) {
  std::map<std::string, std::unique_ptr<eprosima::fastdds::dds::TopicDataType>> dds_supports;
  for (auto& support : generated_dds_type_supports()) {
    dds_supports[support->getName()] = std::move(support);
  }
  std::mt19937 random(42);
  for (const MessageType* type : generated_message_types()) {
    SCOPED_TRACE(type->name());
    IdlSchema schema;
    schema.parse(full_definition(*type));
    ASSERT_TRUE(dds_supports.contains(type->dds_name()));
    auto& dds = *dds_supports[type->dds_name()];
    for (int trial = 0; trial < 25; ++trial) {
      std::vector<uint8_t> bytes = test::random_cdr(schema, type->name(), random);
      auto message = type->create();
      ASSERT_NO_THROW(type->deserialize(bytes, message.get()));
      EXPECT_EQ(type->serialized_size(message.get()), bytes.size());
      EXPECT_EQ(serialize(*type, message.get()), bytes);

      SerializedPayload_t payload(static_cast<uint32_t>(bytes.size() + 8));
      ASSERT_TRUE(dds.serialize(message.get(), &payload));
      EXPECT_EQ(std::vector<uint8_t>(payload.data, payload.data + payload.length), bytes);

      void* from_dds = dds.createData();
      ASSERT_TRUE(dds.deserialize(&payload, from_dds));
      EXPECT_EQ(serialize(*type, from_dds), bytes);
      dds.deleteData(from_dds);

      EXPECT_FALSE(format_cdr(schema, type->name(), bytes).empty());
    }
  }
}

TEST(Messages, TypedValuesSurviveTheRoundTrip) {
  mocap_msgs::msg::FiducialArray array;
  array.header().frame_id("camera");
  array.header().stamp(to_time_msg(
      std::chrono::system_clock::time_point(std::chrono::nanoseconds(1732180000123456789))));
  for (int i = 0; i < 12; ++i) {
    mocap_msgs::msg::Fiducial f;
    f.x(10.5f * i);
    f.y(-3.25f * i);
    f.z(1.0f);
    f.size(4.0f + i);
    f.uncertainty(0.01f * i);
    array.fiducials().push_back(f);
  }
  const MessageType& type = message_type<mocap_msgs::msg::FiducialArray>();
  std::vector<uint8_t> bytes = serialize(type, &array);
  mocap_msgs::msg::FiducialArray copy;
  type.deserialize(bytes, &copy);
  EXPECT_EQ(copy, array);
  EXPECT_EQ(copy.header().stamp().sec(), 1732180000);
  EXPECT_EQ(copy.header().stamp().nanosec(), 123456789u);
  EXPECT_EQ(from_time_msg(copy.header().stamp()).time_since_epoch(),
            std::chrono::nanoseconds(1732180000123456789));
}

TEST(Messages, MalformedDataIsAnErrorNotACrash) {
  sensor_msgs::msg::Image image;
  image.width(4);
  image.height(2);
  image.encoding("mono8");
  image.step(4);
  image.data(std::vector<uint8_t>(8, 7));
  const MessageType& type = message_type<sensor_msgs::msg::Image>();
  std::vector<uint8_t> bytes = serialize(type, &image);
  for (size_t cut : {size_t(0), size_t(3), size_t(10), bytes.size() - 1}) {
    SCOPED_TRACE(cut);
    sensor_msgs::msg::Image out;
    std::vector<uint8_t> truncated(bytes.begin(), bytes.begin() + static_cast<long>(cut));
    EXPECT_THROW(type.deserialize(truncated, &out), SerializationError);
  }
  // A data length claiming 4 GiB.
  std::vector<uint8_t> lying = bytes;
  size_t length_at = bytes.size() - 8 - 4;
  lying[length_at] = lying[length_at + 1] = lying[length_at + 2] = lying[length_at + 3] = 0xff;
  sensor_msgs::msg::Image out;
  EXPECT_THROW(type.deserialize(lying, &out), SerializationError);
  std::vector<uint8_t> small(4);
  EXPECT_THROW(type.serialize(&image, small), SerializationError);
}

}  // namespace
}  // namespace mocap
