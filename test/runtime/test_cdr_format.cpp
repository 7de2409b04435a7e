// Reading IDL and showing CDR without generated code, as mocap_topic echo does.
#include <gtest/gtest.h>

#include <mocap_msgs/msg/constellation_pose_array.hpp>
#include <sensor_msgs/msg/image.hpp>

#include "messages/cdr_format.hpp"
#include "messages/idl_schema.hpp"

namespace mocap {
namespace {

template <class T>
std::vector<uint8_t> serialize(const T& message) {
  const MessageType& type = message_type<T>();
  std::vector<uint8_t> bytes(type.serialized_size(&message));
  bytes.resize(type.serialize(&message, bytes));
  return bytes;
}

template <class T>
IdlSchema schema_of() {
  IdlSchema schema;
  schema.parse(full_definition(message_type<T>()));
  return schema;
}

TEST(CdrFormat, NestedStructsListsAndArrays) {
  mocap_msgs::msg::ConstellationPoseArray array;
  array.header().frame_id("cam");
  array.header().stamp().sec(5);
  mocap_msgs::msg::ConstellationPose pose;
  pose.name("A");
  pose.pose().pose().position().x(1.5);
  pose.pose().pose().orientation().w(1.0);
  pose.covariance()[0] = 0.25;
  pose.reprojection_rms_px(0.5f);
  pose.points_used(12);
  pose.cameras_used(3);
  array.poses().push_back(pose);
  std::string text =
      format_cdr(schema_of<mocap_msgs::msg::ConstellationPoseArray>(),
                 "mocap_msgs/msg/ConstellationPoseArray", serialize(array), {.max_items = 4});
  EXPECT_EQ(text, R"(header:
  stamp:
    sec: 5
    nanosec: 0
  frame_id: "cam"
poses:
  - name: "A"
    pose:
      header:
        stamp:
          sec: 0
          nanosec: 0
        frame_id: ""
      pose:
        position:
          x: 1.5
          y: 0
          z: 0
        orientation:
          x: 0
          y: 0
          z: 0
          w: 1
    covariance: [0.25, 0, 0, 0, ...] # 36 items
    reprojection_rms_px: 0.5
    points_used: 12
    velocity:
      linear:
        x: 0
        y: 0
        z: 0
      angular:
        x: 0
        y: 0
        z: 0
    velocity_covariance: [0, 0, 0, 0, ...] # 36 items
    cameras_used: 3
data_received:
  sec: 0
  nanosec: 0
cameras_late: 0
)");
}

TEST(CdrFormat, LongByteSequencesAreCut) {
  sensor_msgs::msg::Image image;
  image.encoding("mono8");
  image.data(std::vector<uint8_t>(1000, 9));
  image.step(7);
  std::string text = format_cdr(schema_of<sensor_msgs::msg::Image>(), "sensor_msgs/msg/Image",
                                serialize(image), {.max_items = 3});
  EXPECT_NE(text.find("data: [9, 9, 9, ...] # 1000 items\n"), std::string::npos) << text;
  EXPECT_NE(text.find("step: 7\n"), std::string::npos) << text;
}

TEST(CdrFormat, MalformedData) {
  auto schema = schema_of<sensor_msgs::msg::Image>();
  auto bytes = serialize(sensor_msgs::msg::Image());
  bytes.resize(bytes.size() - 2);
  EXPECT_THROW(format_cdr(schema, "sensor_msgs/msg/Image", bytes), SerializationError);
  EXPECT_THROW(format_cdr(schema, "sensor_msgs/msg/Image", std::vector<uint8_t>{0, 3, 0, 0}),
               SerializationError);  // parameter-list (mutable) encapsulation
  EXPECT_THROW(format_cdr(schema, "sensor_msgs/msg/Nothing", bytes), IdlError);
}

// The form ROS 2's rosidl writes: typedefs for arrays, constants, annotations, enums.
TEST(IdlSchema, ReadsRos2StyleIdl) {
  IdlSchema schema;
  schema.parse(R"(
#include "std_msgs/msg/Header.idl"
module geometry_msgs {
  module msg {
    typedef double double__36[36];
    module PoseWithCovariance_Constants {
      const uint8 SIZE = 36;
    };
    @verbatim (language="comment", text="A pose with covariance.")
    struct PoseWithCovariance {
      @default (value=1.0)
      double x, y;
      double__36 covariance;
      sequence<string<10>, 5> names;
      unsigned long long big;
    };
  };
};
)");
  const IdlStruct* type = schema.find("geometry_msgs/msg/PoseWithCovariance");
  ASSERT_NE(type, nullptr);
  ASSERT_EQ(type->members.size(), 5u);
  EXPECT_EQ(type->members[1].name, "y");
  EXPECT_EQ(type->members[2].type.kind, IdlKind::Double);
  EXPECT_EQ(type->members[2].type.array, std::vector<uint32_t>{36});
  EXPECT_EQ(type->members[3].type.kind, IdlKind::Sequence);
  EXPECT_EQ(type->members[3].type.element->kind, IdlKind::String);
  EXPECT_EQ(type->members[4].type.kind, IdlKind::UInt64);
}

TEST(IdlSchema, TruncatedTextIsAnError) {
  for (const char* text :
       {"module a { enum E { X", "module a { const long X = 1", "module a { struct S {"}) {
    IdlSchema schema;
    EXPECT_THROW(schema.parse(text), IdlError) << text;
  }
}

TEST(CdrFormat, AStructContainingItselfIsAnError) {
  IdlSchema schema;
  schema.parse("module a { struct S { long x; a::S s; }; };");
  std::vector<uint8_t> bytes(4096, 0);
  bytes[1] = 1;
  EXPECT_THROW(format_cdr(schema, "a::S", bytes), IdlError);
}

TEST(IdlSchema, ErrorsNameTheLine) {
  IdlSchema schema;
  try {
    schema.parse("module a {\n  struct B {\n    long double x;\n  };\n};\n");
    FAIL();
  } catch (const IdlError& e) {
    EXPECT_STREQ(e.what(), "IDL line 3: long double is not supported");
  }
}

}  // namespace
}  // namespace mocap
