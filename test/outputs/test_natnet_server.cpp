// The NatNet server: its packets byte for byte as NatNet's description lays them out, the bodies
// and fused frames as NatNet clients are told of them, and the server and plugin read by a client
// of its own (test/outputs/natnet_client.mjs, written from the description alone).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <random>
#include <sstream>
#include <thread>

#include <mocap/component_host.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>
#include <nlohmann/json.hpp>
#include <sensor_msgs/msg/point_cloud2.hpp>

#include "common/marker_cloud_message/marker_cloud_message.hpp"
#include "common/pose_message/pose_message.hpp"
#include "host/plugin_loader.hpp"
#include "outputs/natnet_server/natnet_frames.hpp"
#include "outputs/natnet_server/natnet_server.hpp"
#include "test/test_support.hpp"

namespace mocap::natnet {
namespace {

using json = nlohmann::json;
using Eigen::Quaternionf;
using Eigen::Vector3f;

// --- bytes as the description lays them out ---------------------------------------------------

template <typename T>
std::string le(T value) {
  std::string bytes(sizeof(T), '\0');
  std::memcpy(bytes.data(), &value, sizeof(T));
  return bytes;
}
std::string i32(int32_t v) { return le(v); }
std::string f32(float v) { return le(v); }
std::string cstr(const std::string& text) { return text + std::string(1, '\0'); }
std::string vec(float x, float y, float z) { return f32(x) + f32(y) + f32(z); }
std::string packet(uint16_t id, const std::string& payload) {
  return le(id) + le(static_cast<uint16_t>(payload.size())) + payload;
}

TEST(NatNetProtocol, ServerInfoIsSSenderServerPacked) {
  ServerDescription server;
  server.natnet = {4, 2};
  server.data_port = 1511;
  server.multicast = true;
  const std::string bytes = encode_server_info(server);
  std::string expected = "mocap-graph";
  expected.resize(256, '\0');
  expected += std::string("\x01\x00\x00\x00", 4) + std::string("\x04\x02\x00\x00", 4) +
              le(uint64_t{1'000'000'000}) + le(uint16_t{1511}) + std::string(1, '\x01') +
              std::string("\xEF\xFF\x2A\x63", 4);
  ASSERT_EQ(expected.size(), 279u);
  EXPECT_EQ(bytes, packet(kServerInfo, expected));
}

Descriptions one_body() {
  Descriptions descriptions;
  descriptions.marker_sets.push_back({"b", {"b_1", "b_2"}});
  RigidBodyDescription body;
  body.name = "b";
  body.id = 3;
  body.markers = {Vector3f(0.1f, 0, 0), Vector3f(0, 0.2f, 0)};
  body.marker_names = {"b_1", "b_2"};
  descriptions.rigid_bodies.push_back(body);
  return descriptions;
}

TEST(NatNetProtocol, BodyDescriptionsInEachVersionsLayout) {
  const std::string marker_set = cstr("b") + i32(2) + cstr("b_1") + cstr("b_2");
  const std::string head = cstr("b") + i32(3) + i32(-1) + vec(0, 0, 0);
  const std::string markers = i32(2) + vec(0.1f, 0, 0) + vec(0, 0.2f, 0) + i32(0) + i32(0);
  const std::string names = cstr("b_1") + cstr("b_2");
  const std::string orientation = f32(0) + f32(0) + f32(0) + f32(1);
  auto sized = [](const std::string& body) {
    return i32(static_cast<int32_t>(body.size())) + body;
  };
  // 3.0: no marker names; 4.0: names; 4.1: each description's size; 4.2: orientation offset.
  EXPECT_EQ(encode_descriptions(one_body(), {3, 0}),
            packet(kModelDef, i32(2) + i32(0) + marker_set + i32(1) + head + markers));
  EXPECT_EQ(encode_descriptions(one_body(), {4, 0}),
            packet(kModelDef, i32(2) + i32(0) + marker_set + i32(1) + head + markers + names));
  EXPECT_EQ(encode_descriptions(one_body(), {4, 1}),
            packet(kModelDef,
                   i32(2) + i32(0) + sized(marker_set) + i32(1) + sized(head + markers + names)));
  EXPECT_EQ(encode_descriptions(one_body(), {4, 2}),
            packet(kModelDef, i32(2) + i32(0) + sized(marker_set) + i32(1) +
                                  sized(head + orientation + markers + names)));
  // A later 4.x is written as 4.2.
  EXPECT_EQ(encode_descriptions(one_body(), {4, 3}), encode_descriptions(one_body(), {4, 2}));
}

FrameOfData small_frame() {
  FrameOfData frame;
  frame.frame_number = 7;
  frame.marker_sets.push_back({"b", {Vector3f(1, 2, 3)}});
  frame.other_markers = {Vector3f(4, 5, 6)};
  RigidBodyData body;
  body.id = 3;
  body.position = Vector3f(0.5f, -1, 2);
  body.orientation = Quaternionf(0.5f, 0.5f, -0.5f, 0.5f);  // w, x, y, z
  body.mean_error_m = 0.00025f;
  body.tracking_valid = true;
  frame.rigid_bodies = {body};
  LabeledMarkerData marker;
  marker.id = (3 << 16) | 1;
  marker.position = Vector3f(1, 2, 3);
  marker.size_m = 0.014f;
  marker.flags = kHasModel | kPointCloudSolved;
  marker.residual_m = 0.0001f;
  frame.labeled_markers = {marker};
  frame.timestamp_s = 1.5;
  frame.stamps = {1'700'000'000'000'000'000, 1'700'000'000'001'000'000, 0};
  frame.tracked_models_changed = true;
  return frame;
}

TEST(NatNetProtocol, FramesInEachVersionsLayout) {
  const std::string sets = cstr("b") + i32(1) + vec(1, 2, 3);
  const std::string other = vec(4, 5, 6);
  const std::string body = i32(3) + vec(0.5f, -1, 2) + f32(0.5f) + f32(-0.5f) + f32(0.5f) +
                           f32(0.5f) + f32(0.00025f) + le(int16_t{1});
  const std::string marker = i32((3 << 16) | 1) + vec(1, 2, 3) + f32(0.014f) +
                             le(int16_t{kHasModel | kPointCloudSolved}) + f32(0.0001f);
  const std::string stamps = le(uint64_t{1'700'000'000'000'000'000}) +
                             le(uint64_t{1'700'000'000'001'000'000}) + le(uint64_t{0});
  const std::string suffix_head = le(uint32_t{0}) + le(uint32_t{0}) + le(1.5) + stamps;
  const std::string end = le(int16_t{0x02}) + i32(0);
  auto section = [](int32_t count, const std::string& items) {
    return i32(count) + i32(static_cast<int32_t>(items.size())) + items;
  };
  EXPECT_EQ(encode_frame(small_frame(), {3, 1}),
            packet(kFrameOfData, i32(7) + i32(1) + sets + i32(1) + other + i32(1) + body +
                                     i32(0) /*skeletons*/ + i32(1) + marker + i32(0) /*plates*/ +
                                     i32(0) /*devices*/ + suffix_head + end));
  EXPECT_EQ(
      encode_frame(small_frame(), {4, 1}),
      packet(kFrameOfData, i32(7) + section(1, sets) + section(1, other) + section(1, body) +
                               section(0, "") /*skeletons*/ + section(0, "") /*assets*/ +
                               section(1, marker) + section(0, "") + section(0, "") + suffix_head +
                               le(uint32_t{0}) + le(uint32_t{0}) /*precision*/ + end));
  // What differs between clients' copies: the transmit stamp and the bitstream-changed flag.
  std::string copy = encode_frame(small_frame(), {4, 1});
  set_transmit_stamp(copy, {4, 1}, 0x0102030405060708);
  set_bitstream_changed(copy, true);
  std::string expected = encode_frame(small_frame(), {4, 1});
  const size_t transmit_at = expected.size() - 4 - 2 - 8 - 8;
  expected.replace(transmit_at, 8, le(uint64_t{0x0102030405060708}));
  expected.replace(expected.size() - 6, 2, le(int16_t{0x0A}));
  EXPECT_EQ(copy, expected);
}

TEST(NatNetProtocol, RequestsAsOptiTracksClientsSendThem) {
  std::string problem;
  // The Python sample's connect: 270 bytes and a NUL, version 4.2 at byte 265.
  std::string python(270, '\0');
  python.replace(0, 4, "Ping");
  python[265] = 4;
  python[266] = 2;
  std::string datagram = le(uint16_t{kConnect}) + le(uint16_t{271}) + python + std::string(1, '\0');
  std::optional<Request> request = parse_request(datagram, &problem);
  ASSERT_TRUE(request) << problem;
  EXPECT_EQ(requested_version(*request), (Version{4, 2}));
  // PacketClient's: sSender, sConnectionOptions and 4 bytes, version 0: the server's choice.
  request = parse_request(packet(kConnect, std::string(273, '\0')), &problem);
  ASSERT_TRUE(request) << problem;
  EXPECT_FALSE(requested_version(*request));
  // libmotioncapture's: the header alone.
  request = parse_request(packet(kConnect, ""), &problem);
  ASSERT_TRUE(request) << problem;
  EXPECT_FALSE(requested_version(*request));
  // A keep-alive with the Python sample's extra NUL; a request's text.
  EXPECT_TRUE(parse_request(packet(kKeepAlive, "") + std::string(1, '\0'), &problem));
  request = parse_request(packet(kRequest, cstr("Bitstream,3.1")), &problem);
  ASSERT_TRUE(request);
  EXPECT_EQ(command_text(*request), "Bitstream,3.1");
  // Not NatNet: too short, a size that lies, a message only servers send.
  EXPECT_FALSE(parse_request("\x02", &problem));
  EXPECT_EQ(problem, "1 bytes: shorter than a NatNet header");
  EXPECT_FALSE(
      parse_request(le(uint16_t{kRequest}) + le(uint16_t{50}) + cstr("FrameRate"), &problem));
  EXPECT_EQ(problem, "message 2 says 50 payload bytes, the datagram holds 10");
  EXPECT_FALSE(parse_request(packet(kFrameOfData, ""), &problem));
  EXPECT_EQ(problem, "message id 7 is no NatNet request");
  EXPECT_FALSE(parse_request(packet(500, ""), &problem));

  EXPECT_EQ(parse_version("4.1"), (Version{4, 1}));
  EXPECT_EQ(parse_version("3.1.0.0"), (Version{3, 1}));
  for (const char* bad : {"", "4", "4.", "4.x", "256.1", "4.1.0.0.0", "-1.0"}) {
    EXPECT_FALSE(parse_version(bad)) << bad;
  }
}

// --- what clients are told of the bodies and frames --------------------------------------------

TEST(NatNetFrames, StreamingIdsAreTheFilesOrElseTheLowestFree) {
  volume::RigidBodyDatabase bodies;
  bodies.bodies = {{"wand", {{0, 0, 0}, {0.1, 0, 0}, {0, 0.1, 0}}},
                   {"drone", {{0, 0, 0}, {0.1, 0, 0}, {0, 0.2, 0}}, 1}};
  volume::SwarmDatabase robots;
  robots.layouts = {{"single", {{0, 0, 0}}}};
  robots.robots = {{"r1", 0, {1, 0, 0}}, {"r2", 0, {2, 0, 0}, 3}};
  const std::vector<StreamedBody> streamed = streamed_bodies(bodies, robots);
  ASSERT_EQ(streamed.size(), 4u);
  EXPECT_EQ(streamed[0].name, "wand");
  EXPECT_EQ(streamed[0].id, 2);
  EXPECT_EQ(streamed[1].id, 1);
  EXPECT_EQ(streamed[2].name, "r1");
  EXPECT_EQ(streamed[2].id, 4);
  EXPECT_EQ(streamed[2].markers.size(), 1u);
  EXPECT_EQ(streamed[3].id, 3);

  robots.robots[1].streaming_id = 1;
  EXPECT_THROW(
      try { streamed_bodies(bodies, robots); } catch (const volume::RigidBodyError& e) {
        EXPECT_STREQ(e.what(), "'drone' and 'r2' have streaming_id 1");
        throw;
      },
      volume::RigidBodyError);
  robots.robots[1] = {"wand", 0, {2, 0, 0}};
  EXPECT_THROW(streamed_bodies(bodies, robots), volume::RigidBodyError);
}

TEST(NatNetFrames, BodiesFilesNameTheirStreamingIdsLineByLine) {
  const std::string text =
      "bodies:\n"
      "  - {name: a, markers: [[0, 0, 0], [0.1, 0, 0], [0, 0.13, 0]], streaming_id: 5}\n"
      "  - {name: b, markers: [[0, 0, 0], [0.2, 0, 0], [0, 0.3, 0]], streaming_id: 5}\n";
  try {
    volume::parse_rigid_bodies(text, "bodies.yaml", 0, 3);
    ADD_FAILURE() << "accepted";
  } catch (const volume::RigidBodyError& e) {
    EXPECT_NE(std::string(e.what()).find("bodies.yaml:3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("bodies 'a' and 'b' have streaming_id 5"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(volume::parse_rigid_bodies(
                "bodies:\n  - {name: a, markers: [[0, 0, 0], [0.1, 0, 0], [0, 0.13, 0]], "
                "streaming_id: 9}\n",
                "bodies.yaml", 0, 3)
                .bodies[0]
                .streaming_id,
            9);
  EXPECT_THROW(volume::parse_rigid_bodies("bodies:\n  - {name: a, markers: [[0, 0, 0], [0.1, 0, "
                                          "0], [0, 0.13, 0]], streaming_id: 40000}\n",
                                          "bodies.yaml", 0, 3),
               volume::RigidBodyError);
}

Eigen::Isometry3d pose_of(const Eigen::Vector3d& position, double angle) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = position;
  pose.linear() =
      Eigen::AngleAxisd(angle, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  return pose;
}

TEST(NatNetFrames, MarkersAreLabeledByBodyAndBodiesKeepTheirLastPose) {
  const std::vector<StreamedBody> known = {{"board", 4, {{0, 0, 0}, {0.1, 0, 0}, {0, 0.1, 0}}},
                                           {"robot", 9, {{0, 0, 0}}}};
  FrameBuilder builder(known, {.legacy_markers = LegacyMarkers::unlabeled});
  const Eigen::Isometry3d board = pose_of({1, 2, 0.5}, 0.3);
  FusedFrame fused;
  fused.capture_ns = 1'000'000'000;
  fused.data_received_ns = 1'002'000'000;
  fused.bodies = {{"board", board}};
  const Eigen::Vector3d seen = board * Eigen::Vector3d(0.1, 0, 0) + Eigen::Vector3d(0.001, 0, 0);
  fused.markers = {{seen.cast<float>(), 0, 1, 77}, {Vector3f(5, 5, 5), -1, 0, 0x12345}};
  bool changed = true;
  FrameOfData frame = builder.build(fused, &changed);
  EXPECT_FALSE(changed);
  ASSERT_EQ(frame.rigid_bodies.size(), 2u);
  EXPECT_EQ(frame.rigid_bodies[0].id, 4);
  EXPECT_TRUE(frame.rigid_bodies[0].tracking_valid);
  EXPECT_TRUE(frame.rigid_bodies[0].position.isApprox(Vector3f(1, 2, 0.5f)));
  EXPECT_NEAR(frame.rigid_bodies[0].mean_error_m, 0.001, 1e-6);
  EXPECT_FALSE(frame.rigid_bodies[1].tracking_valid);
  ASSERT_EQ(frame.labeled_markers.size(), 2u);
  EXPECT_EQ(frame.labeled_markers[0].id, (4 << 16) | 2);
  EXPECT_EQ(frame.labeled_markers[0].flags, kHasModel | kPointCloudSolved);
  EXPECT_NEAR(frame.labeled_markers[0].residual_m, 0.001, 1e-6);
  EXPECT_EQ(frame.labeled_markers[1].id, 0x2345);
  EXPECT_EQ(frame.labeled_markers[1].flags, kUnlabeled | kPointCloudSolved);
  ASSERT_EQ(frame.other_markers.size(), 1u);
  EXPECT_EQ(frame.other_markers[0], Vector3f(5, 5, 5));
  // The board's marker set: its second marker where seen, the others where its pose puts them.
  ASSERT_EQ(frame.marker_sets.size(), 2u);
  EXPECT_EQ(frame.marker_sets[0].positions[1], seen.cast<float>());
  EXPECT_TRUE(frame.marker_sets[0].positions[2].isApprox(
      (board * Eigen::Vector3d(0, 0.1, 0)).cast<float>()));
  EXPECT_EQ(frame.stamps.camera_mid_exposure, 1'000'000'000u);
  EXPECT_EQ(frame.stamps.camera_data_received, 1'002'000'000u);
  EXPECT_EQ(frame.timestamp_s, 0);

  // Next frame: the board lost (its last pose, not valid); a body no file named gets id 10.
  fused.capture_ns = 1'010'000'000;
  fused.bodies = {{"stranger", pose_of({0, 0, 1}, 0)}};
  fused.markers.clear();
  frame = builder.build(fused, &changed);
  EXPECT_TRUE(changed);
  EXPECT_NEAR(frame.timestamp_s, 0.01, 1e-12);
  ASSERT_EQ(frame.rigid_bodies.size(), 3u);
  EXPECT_FALSE(frame.rigid_bodies[0].tracking_valid);
  EXPECT_TRUE(frame.rigid_bodies[0].position.isApprox(Vector3f(1, 2, 0.5f)));
  EXPECT_EQ(frame.rigid_bodies[2].id, 10);
  EXPECT_TRUE(frame.rigid_bodies[2].tracking_valid);
  const Descriptions descriptions = builder.descriptions();
  ASSERT_EQ(descriptions.rigid_bodies.size(), 3u);
  EXPECT_EQ(descriptions.rigid_bodies[2].name, "stranger");
  EXPECT_EQ(descriptions.rigid_bodies[0].marker_names,
            (std::vector<std::string>{"board_1", "board_2", "board_3"}));
  EXPECT_EQ(descriptions.marker_sets.size(), 2u);  // the stranger has no markers
}

TEST(NatNetFrames, YUpIsMotivesAxes) {
  FrameBuilderOptions options;
  options.up_axis = UpAxis::y_up;
  FrameBuilder builder({{"b", 1, {{0.1, 0, 0}, {0, 0.1, 0}, {0, 0, 0.1}}}}, options);
  const Eigen::Isometry3d pose = pose_of({1, 2, 3}, 0.7);
  FusedFrame fused;
  fused.bodies = {{"b", pose}};
  fused.markers = {{Vector3f(1, 2, 3), -1, 0, 1}};
  const FrameOfData frame = builder.build(fused, nullptr);
  // Up is y: our z goes to y, our y to -z.
  EXPECT_TRUE(frame.rigid_bodies[0].position.isApprox(Vector3f(1, 3, -2)));
  EXPECT_EQ(frame.labeled_markers[0].position, Vector3f(1, 3, -2));
  EXPECT_TRUE(frame.other_markers.empty());  // the legacy list: none by default
  // The body's own axes in Motive's world: ours through the same change of axes.
  Eigen::Matrix3d y_up_from_ours;
  y_up_from_ours << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  const Eigen::Matrix3d expected = y_up_from_ours * pose.linear();
  EXPECT_TRUE(
      frame.rigid_bodies[0].orientation.toRotationMatrix().cast<double>().isApprox(expected, 1e-6));
}

// --- the server and an independent client ------------------------------------------------------

// Frames at 100 Hz while a test runs: body 3 turning, body 5 not tracked; a labeled marker, an
// unlabeled one; capture k at base + 10 ms k, its data received 1.234567 ms later.
constexpr int64_t kBaseNs = 1'700'000'000'000'000'000;
constexpr int64_t kReceivedAfterNs = 1'234'567;

FrameOfData reported_frame(int k) {
  FrameOfData frame;
  RigidBodyData turning;
  turning.id = 3;
  turning.position = Vector3f(0.1f * static_cast<float>(k % 100), -1.25f, 2.5f);
  turning.orientation = Quaternionf(
      Eigen::AngleAxisf(0.01f * static_cast<float>(k % 100), Vector3f(1, 2, 3).normalized()));
  turning.mean_error_m = 0.0002f;
  turning.tracking_valid = true;
  RigidBodyData lost;
  lost.id = 5;
  frame.rigid_bodies = {turning, lost};
  frame.marker_sets = {{"b", {Vector3f(1, 2, 3), Vector3f(4, 5, 6)}}};
  frame.labeled_markers = {{(3 << 16) | 1, Vector3f(1, 2, 3), 0.014f, kHasModel, 0.0001f},
                           {k % 1000, Vector3f(-1, 0.5f, 0.25f), 0.014f, kUnlabeled, 0}};
  frame.other_markers = {Vector3f(-1, 0.5f, 0.25f)};
  frame.timestamp_s = 0.01 * k;
  frame.stamps.camera_mid_exposure = static_cast<uint64_t>(kBaseNs + int64_t{k} * 10'000'000);
  frame.stamps.camera_data_received = frame.stamps.camera_mid_exposure + kReceivedAfterNs;
  return frame;
}

class Reporter {
 public:
  explicit Reporter(Server& server) : server_(server) {
    thread_ = std::thread([this] {
      for (int k = 0; !stop_; ++k) {
        server_.send_frame(reported_frame(k));
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
    });
  }
  ~Reporter() {
    stop_ = true;
    thread_.join();
  }

 private:
  Server& server_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

std::filesystem::path client_script() {
  return test::source_dir() / "test" / "outputs" / "natnet_client.mjs";
}

std::vector<json> json_lines(const std::string& output) {
  std::vector<json> events;
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    if (!line.empty() && line[0] == '{') events.push_back(json::parse(line));
  }
  return events;
}

std::vector<json> run_client(std::vector<std::string> arguments, int expected_code = 0) {
  std::vector<std::string> argv = {"node", client_script().string()};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  auto [code, output] = test::run_command(argv, {}, std::chrono::seconds(60));
  EXPECT_EQ(code, expected_code) << output;
  return json_lines(output);
}

float float_of(int32_t bits) {
  float value = 0;
  std::memcpy(&value, &bits, 4);
  return value;
}

std::vector<json> of_type(const std::vector<json>& events, const std::string& type) {
  std::vector<json> found;
  for (const json& event : events) {
    if (event["type"] == type) found.push_back(event);
  }
  return found;
}

// Every frame the client decoded is the frame reported: values to the bit of a float, stamps
// exactly, camera latency (received - mid-exposure) and software latency as sent.
void expect_frames_as_reported(const std::vector<json>& events, const std::string& version) {
  const std::vector<json> frames = of_type(events, "frame");
  ASSERT_GE(frames.size(), 10u);
  int previous = -1;
  for (const json& frame : frames) {
    EXPECT_EQ(frame["version"], version + ".0.0");
    const uint64_t mid = std::stoull(frame["camera_mid_exposure"].get<std::string>());
    const int k = static_cast<int>((static_cast<int64_t>(mid) - kBaseNs) / 10'000'000);
    const FrameOfData sent = reported_frame(k);
    if (previous >= 0) {
      EXPECT_EQ(frame["frame_number"].get<int>(), previous + 1);
    }
    previous = frame["frame_number"].get<int>();
    EXPECT_EQ(std::stoull(frame["camera_data_received"].get<std::string>()) - mid,
              static_cast<uint64_t>(kReceivedAfterNs));
    const uint64_t transmit = std::stoull(frame["transmit"].get<std::string>());
    EXPECT_GE(transmit, mid + kReceivedAfterNs);  // the reporter runs on today's clock
    EXPECT_DOUBLE_EQ(frame["timestamp"].get<double>(), sent.timestamp_s);
    ASSERT_EQ(frame["rigid_bodies"].size(), 2u) << frame;
    const json& body = frame["rigid_bodies"][0];
    EXPECT_EQ(body["id"], 3);
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(body["position"][i].get<float>(), sent.rigid_bodies[0].position[i]);
    }
    const Quaternionf& q = sent.rigid_bodies[0].orientation;
    const float expected[4] = {q.x(), q.y(), q.z(), q.w()};
    for (int i = 0; i < 4; ++i) EXPECT_EQ(body["orientation"][i].get<float>(), expected[i]);
    EXPECT_EQ(body["mean_error"].get<float>(), 0.0002f);
    EXPECT_TRUE(body["tracking_valid"].get<bool>());
    EXPECT_FALSE(frame["rigid_bodies"][1]["tracking_valid"].get<bool>());
    ASSERT_EQ(frame["labeled_markers"].size(), 2u);
    EXPECT_EQ(frame["labeled_markers"][0]["model_id"], 3);
    EXPECT_EQ(frame["labeled_markers"][0]["marker_id"], 1);
    EXPECT_TRUE(frame["labeled_markers"][0]["has_model"].get<bool>());
    EXPECT_TRUE(frame["labeled_markers"][1]["unlabeled"].get<bool>());
    EXPECT_EQ(frame["labeled_markers"][1]["marker_id"], k % 1000);
    EXPECT_EQ(frame["unlabeled_markers"].size(), 1u);
    EXPECT_EQ(frame["marker_sets"][0]["name"], "b");
  }
}

TEST(NatNetServer, ClientsOfEachVersionReadDescriptionsAndEveryFrame) {
  Server server({.command_port = 0});
  server.set_descriptions(one_body());
  Reporter reporter(server);
  const std::string port = std::to_string(server.command_port());
  for (const std::string version : {"4.2", "4.1", "4.0", "3.1", "3.0"}) {
    SCOPED_TRACE(version);
    const std::vector<json> events =
        run_client({"--server", "127.0.0.1", "--command-port", port, "--version", version,
                    "--frames", "12", "--requests", "FrameRate;UnitsToMillimeters;Nonsense"});
    const std::vector<json> info = of_type(events, "server_info");
    ASSERT_EQ(info.size(), 1u);
    EXPECT_EQ(info[0]["application"], "mocap-graph");
    EXPECT_EQ(info[0]["natnet_version"], version + ".0.0");
    EXPECT_EQ(info[0]["high_resolution_clock_frequency"], "1000000000");
    EXPECT_FALSE(info[0]["multicast"].get<bool>());
    const std::vector<json> descriptions = of_type(events, "descriptions");
    ASSERT_EQ(descriptions.size(), 1u);
    ASSERT_EQ(descriptions[0]["rigid_bodies"].size(), 1u);
    const json& body = descriptions[0]["rigid_bodies"][0];
    EXPECT_EQ(body["name"], "b");
    EXPECT_EQ(body["id"], 3);
    EXPECT_EQ(body["parent_id"], -1);
    EXPECT_EQ(body["markers"][1]["position"][1].get<float>(), 0.2f);
    if (version >= "4.0") {
      EXPECT_EQ(body["markers"][1]["name"], "b_2");
    }
    // FrameRate and UnitsToMillimeters answer a float (4 bytes: the client reads a code).
    const std::vector<json> responses = of_type(events, "response");
    ASSERT_EQ(responses.size(), 2u);
    EXPECT_NEAR(float_of(responses[0]["code"].get<int32_t>()), 100, 20);
    EXPECT_EQ(float_of(responses[1]["code"].get<int32_t>()), 1000.0f);
    EXPECT_EQ(of_type(events, "unrecognized").size(), 1u);
    expect_frames_as_reported(events, version);
  }
  // The same client switching to 3.1 by the Bitstream command.
  const std::vector<json> events =
      run_client({"--server", "127.0.0.1", "--command-port", port, "--version", "4.2",
                  "--bitstream", "3.1", "--frames", "12"});
  ASSERT_EQ(of_type(events, "response").size(), 1u);
  EXPECT_EQ(of_type(events, "response")[0]["code"], 0);
  expect_frames_as_reported(events, "3.1");
}

// A raw UDP socket on loopback, for what no well-behaved client sends.
class RawSocket {
 public:
  // On `local`: 127.0.0.1, or another loopback address to be another source.
  explicit RawSocket(const char* local_address = "127.0.0.1")
      : fd_(::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0)) {
    sockaddr_in local{};
    local.sin_family = AF_INET;
    inet_pton(AF_INET, local_address, &local.sin_addr);
    ::bind(fd_, reinterpret_cast<sockaddr*>(&local), sizeof local);
  }
  ~RawSocket() { ::close(fd_); }
  void send(uint16_t port, const std::string& bytes) const {
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(port);
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
  }
  // Datagrams that come within `wait`, by message id.
  std::map<int, int> receive_for(std::chrono::milliseconds wait) const {
    std::map<int, int> ids;
    const auto until = std::chrono::steady_clock::now() + wait;
    char buffer[1 << 16];
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          until - std::chrono::steady_clock::now());
      if (left.count() <= 0) return ids;
      pollfd fd{fd_, POLLIN, 0};
      if (::poll(&fd, 1, static_cast<int>(left.count())) <= 0) continue;
      const ssize_t n = ::recv(fd_, buffer, sizeof buffer, 0);
      if (n >= 2) ++ids[static_cast<unsigned char>(buffer[0]) | (buffer[1] << 8)];
    }
  }

 private:
  int fd_;
};

// One client floods commands, one connects and never reads (each from an address of its own);
// the others keep every frame and their answers, and the flood draws no more answers than its
// rate allows.
TEST(NatNetServer, AFloodingAndASilentClientLeaveTheOthersTheirRate) {
  Server server({.command_port = 0, .replies_per_s = 20, .reply_burst = 40});
  server.set_descriptions(one_body());
  Reporter reporter(server);
  const uint16_t port = server.command_port();
  RawSocket silent("127.0.0.3");
  silent.send(port, packet(kConnect, ""));
  std::atomic<bool> flooding{true};
  RawSocket flood("127.0.0.2");
  std::thread flooder([&] {
    for (int i = 0; flooding; ++i) {
      flood.send(port, packet(kRequest, cstr("FrameRate")));
      flood.send(port, packet(kRequestModelDef, ""));
      // About 40,000 requests a second: a flood the server keeps up with, so that what is
      // measured is its answers, not the kernel dropping what no server could read.
      if (i % 20 == 19) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  const auto started = std::chrono::steady_clock::now();
  const std::vector<json> events = run_client(
      {"--server", "127.0.0.1", "--command-port", std::to_string(port), "--frames", "150"});
  flooding = false;
  flooder.join();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  expect_frames_as_reported(events, "4.2");  // consecutive frame numbers: none lost
  const std::map<int, int> answered = flood.receive_for(std::chrono::milliseconds(200));
  int answers = 0;
  for (const auto& [id, count] : answered) {
    if (id != kFrameOfData) answers += count;
  }
  EXPECT_LE(answers, 40 + static_cast<int>(20 * (seconds + 0.5)));
  EXPECT_GT(server.stats().replies_limited, 1000u);
  EXPECT_EQ(server.stats().datagrams_dropped, 0u);
}

// At most max_clients; a client silent for client_timeout_s or one that sends what is not
// NatNet is sent to no more.
TEST(NatNetServer, ClientsAreCappedAndForgottenWhenSilentOrForeign) {
  Server server({.command_port = 0, .max_clients = 2, .client_timeout_s = 0.5});
  Reporter reporter(server);
  const uint16_t port = server.command_port();
  RawSocket first, second, third;
  first.send(port, packet(kConnect, ""));
  second.send(port, packet(kConnect, ""));
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  third.send(port, packet(kConnect, ""));
  std::map<int, int> got = third.receive_for(std::chrono::milliseconds(300));
  EXPECT_EQ(got[kMessageString], 1);
  EXPECT_EQ(got[kFrameOfData], 0);
  EXPECT_EQ(server.stats().clients_refused, 1u);
  // The second turns foreign: forgotten at once. The first keeps alive, then falls silent.
  second.send(port, "GET / HTTP/1.1\r\n\r\n");
  first.send(port, packet(kKeepAlive, ""));
  got = first.receive_for(std::chrono::milliseconds(300));
  EXPECT_GT(got[kFrameOfData], 10);
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  EXPECT_EQ(server.clients(), 0u);
  // What came before is still in their sockets; nothing comes after.
  first.receive_for(std::chrono::milliseconds(50));
  second.receive_for(std::chrono::milliseconds(50));
  EXPECT_EQ(first.receive_for(std::chrono::milliseconds(200))[kFrameOfData], 0);
  EXPECT_EQ(second.receive_for(std::chrono::milliseconds(200))[kFrameOfData], 0);
  const ServerStats stats = server.stats();
  EXPECT_EQ(stats.clients_dropped_malformed, 1u);
  EXPECT_EQ(stats.clients_timed_out, 1u);
}

// NAT_CONNECTs from many ports of one address (as forged ones would come): clients are added only
// within the address's answer rate, so they cannot draw streams at will.
TEST(NatNetServer, ConnectsFromOneAddressAreAddedOnlyWithinItsRate) {
  Server server({.command_port = 0, .max_clients = 1000, .replies_per_s = 20, .reply_burst = 40});
  std::vector<std::unique_ptr<RawSocket>> sockets;
  const auto started = std::chrono::steady_clock::now();
  for (int i = 0; i < 300; ++i) {
    sockets.push_back(std::make_unique<RawSocket>("127.0.0.4"));
    sockets.back()->send(server.command_port(), packet(kConnect, ""));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  // The burst, and what the rate refilled meanwhile.
  EXPECT_GE(server.clients(), 40u);
  EXPECT_LE(static_cast<double>(server.clients()), 40 + 20 * seconds + 1);
  EXPECT_EQ(server.clients() + server.stats().replies_limited, 300u);
}

// Whatever comes in at random, the server stays up and a proper client is served.
TEST(NatNetServer, RandomDatagramsLeaveItServing) {
  Server server({.command_port = 0, .replies_per_s = 10000, .reply_burst = 10000});
  server.set_descriptions(one_body());
  Reporter reporter(server);
  RawSocket noise;
  std::mt19937 random(11);
  for (int i = 0; i < 20000; ++i) {
    std::string datagram(random() % 300, '\0');
    for (char& c : datagram) c = static_cast<char>(random());
    if (i % 3 == 0 && datagram.size() >= 4) {  // a plausible header over random bytes
      const auto id = static_cast<uint16_t>(random() % 16);
      const auto size = static_cast<uint16_t>(datagram.size() - 4);
      std::memcpy(&datagram[0], &id, 2);
      std::memcpy(&datagram[2], &size, 2);
    }
    noise.send(server.command_port(), datagram);
  }
  const std::vector<json> events =
      run_client({"--server", "127.0.0.1", "--command-port", std::to_string(server.command_port()),
                  "--frames", "12"});
  expect_frames_as_reported(events, "4.2");
  EXPECT_GT(server.stats().malformed, 1000u);
}

// Multicast: frames to the group on the loopback interface, read by a client that joined it; the
// server info names the group, and NAT_CONNECT adds no unicast client.
TEST(NatNetServer, MulticastReachesAClientThatJoinedTheGroup) {
  Server server({.command_port = 0, .data_port = 0, .multicast = true});
  const int data_port = server.data_port();
  server.set_descriptions(one_body());
  Reporter reporter(server);
  const std::vector<json> events =
      run_client({"--server", "127.0.0.1", "--command-port", std::to_string(server.command_port()),
                  "--local", "127.0.0.1", "--multicast", "239.255.42.99", "--data-port",
                  std::to_string(data_port), "--frames", "12"});
  const std::vector<json> info = of_type(events, "server_info");
  ASSERT_EQ(info.size(), 1u);
  EXPECT_TRUE(info[0]["multicast"].get<bool>());
  EXPECT_EQ(info[0]["multicast_group"], "239.255.42.99");
  EXPECT_EQ(info[0]["data_port"], data_port);
  EXPECT_EQ(info[0]["natnet_version"], "4.1.0.0");  // multicast: one stream, the server's version
  expect_frames_as_reported(events, "4.1");
  EXPECT_EQ(server.clients(), 0u);
}

// natnet_server on host A of two network namespaces: by default only A itself is answered; with
// address 0.0.0.0 in the launch file, B is too, and the server says so once.
TEST(NatNetServer, ListensOnThisMachineOnlyUnlessTheLaunchFileOpensIt) {
  test::TwoHosts hosts;
  if (!hosts.error().empty()) GTEST_SKIP() << "cannot make network namespaces: " << hosts.error();
  test::TempDir dir;
  auto launch = [&](const std::string& parameters, const std::string& name) {
    const std::filesystem::path file = dir / (name + ".yaml");
    test::write_file(file,
                     "groups:\n  - name: g\n    components:\n      - plugin: natnet_server\n"
                     "        name: natnet\n        parameters: {" +
                         parameters + "}\n");
    return std::make_unique<test::ChildProcess>(
        hosts.on_a({(test::bin_dir() / "mocap_launch").string(), file.string()}),
        std::map<std::string, std::string>{
            {"MOCAP_DOMAIN_ID", std::to_string(test::test_domain(76))}},
        dir / (name + ".log"));
  };
  auto descriptions_from = [&](const std::vector<std::string>& prefix, const std::string& address) {
    std::vector<std::string> argv = prefix;
    for (const std::string& arg :
         {std::string("node"), client_script().string(), std::string("--server"), address,
          std::string("--frames"), std::string("0"), std::string("--timeout-s"),
          std::string("3")}) {
      argv.push_back(arg);
    }
    return test::run_command(argv, {}, std::chrono::seconds(30));
  };
  {
    auto graph = launch("", "closed");
    ASSERT_TRUE(graph->wait_for_output("NatNet 4.1 on", std::chrono::seconds(30)))
        << graph->output();
    EXPECT_NE(graph->output().find("on 127.0.0.1:1510"), std::string::npos);
    EXPECT_NE(graph->output().find("(this machine only)"), std::string::npos);
    const auto [code_a, output_a] = descriptions_from(hosts.on_a({}), "127.0.0.1");
    EXPECT_EQ(code_a, 0) << output_a;
    EXPECT_EQ(of_type(json_lines(output_a), "descriptions").size(), 1u) << output_a;
    const auto [code, output] = descriptions_from(hosts.on_b({}), hosts.address_a());
    EXPECT_EQ(code, 1) << output;
    EXPECT_TRUE(of_type(json_lines(output), "server_info").empty()) << output;
  }
  {
    auto graph = launch("address: 0.0.0.0", "open");
    ASSERT_TRUE(graph->wait_for_output("NatNet 4.1 on", std::chrono::seconds(30)))
        << graph->output();
    EXPECT_NE(graph->output().find("Open to the network"), std::string::npos) << graph->output();
    const auto [code, output] = descriptions_from(hosts.on_b({}), hosts.address_a());
    EXPECT_EQ(code, 0) << output;
    EXPECT_EQ(of_type(json_lines(output), "descriptions").size(), 1u) << output;
  }
}

// --- the plugin in a graph ----------------------------------------------------------------------

// Publishes what the fusion publishes: /mocap/poses (frame 'world', with data_received) and the
// /mocap/markers cloud of the same capture.
class FusionFeeder final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.publishes<mocap_msgs::msg::ConstellationPoseArray>("/mocap/poses", Qos::reliable(), "");
    spec.publishes<sensor_msgs::msg::PointCloud2>("/mocap/markers", Qos::sensor_data(), "");
  }
  explicit FusionFeeder(Context& context) : Component(context) {
    poses = create_publisher<mocap_msgs::msg::ConstellationPoseArray>("/mocap/poses");
    markers = create_publisher<sensor_msgs::msg::PointCloud2>("/mocap/markers");
  }
  Publisher<mocap_msgs::msg::ConstellationPoseArray> poses;
  Publisher<sensor_msgs::msg::PointCloud2> markers;
};

const std::vector<Eigen::Vector3d> kWandMarkers = {{0, 0, 0}, {0.1, 0, 0}, {0, 0.13, 0}};

// Capture k: the wand turning and moving, its three markers seen (one 0.5 mm off), a stray marker.
struct FedFrame {
  int64_t capture_ns = 0, received_ns = 0;
  Eigen::Isometry3d wand;
  std::vector<LabeledMarker> markers;
};

FedFrame fed_frame(int k) {
  FedFrame fed;
  fed.capture_ns = kBaseNs + int64_t{k} * 8'333'333;
  fed.received_ns = fed.capture_ns + 1'500'000 + k;
  fed.wand = pose_of({0.01 * k, -0.5, 1.25}, 0.02 * k);
  for (uint16_t m = 0; m < 3; ++m) {
    Eigen::Vector3d p = fed.wand * kWandMarkers[m];
    if (m == 2) p.x() += 0.0005;
    fed.markers.push_back({p.cast<float>(), 0, m, 100u + m, 0.1f, 0b11});
  }
  fed.markers.push_back({Vector3f(2, 2, 0.01f * static_cast<float>(k)), -1, 0, 7u, 0.2f, 0b1});
  return fed;
}

// natnet_server between a feeder of the fusion's messages and the independent client: every pose
// decoded equals the pose published for its capture time to float precision, every marker of the
// cloud is in its frame, and the client's camera latency is capture -> received, its software
// latency received -> transmit.
TEST(NatNetServerPlugin, ServesTheFusionsPosesAndCloudFrameByFrame) {
  test::TempDir dir;
  test::write_file(dir / "bodies.yaml",
                   "bodies:\n  - {name: wand, markers: [[0, 0, 0], [0.1, 0, 0], [0, 0.13, 0]], "
                   "streaming_id: 12}\n");
  const int port = 21000 + test::test_domain(74);
  PluginLoader loader;
  ComponentHost host({.name = "test", .threads = 2, .dds = {.enabled = false}});
  auto& feeder = static_cast<FusionFeeder&>(
      host.add(make_component_factory<FusionFeeder>("feeder"), {.name = "feeder"}));
  host.add(*loader.load("natnet_server").factory,
           {.name = "natnet",
            .parameters = {{"bodies", (dir / "bodies.yaml").string()},
                           {"command_port", static_cast<int64_t>(port)},
                           {"legacy_markers", std::string("all")}}});
  host.start();
  std::atomic<bool> stop{false};
  std::thread publisher([&] {
    for (int k = 0; !stop; ++k) {
      const FedFrame fed = fed_frame(k);
      auto poses = std::make_shared<mocap_msgs::msg::ConstellationPoseArray>();
      poses->header().stamp(to_time_msg(
          std::chrono::system_clock::time_point(std::chrono::nanoseconds(fed.capture_ns))));
      poses->header().frame_id("world");
      poses->data_received(to_time_msg(
          std::chrono::system_clock::time_point(std::chrono::nanoseconds(fed.received_ns))));
      mocap_msgs::msg::ConstellationPose pose;
      pose.name("wand");
      pose.pose().header(poses->header());
      pose.pose().pose(to_pose_message(fed.wand));
      poses->poses().push_back(pose);
      const std_msgs::msg::Header header = poses->header();
      feeder.poses.publish(std::move(poses));
      feeder.markers.publish(
          std::make_shared<sensor_msgs::msg::PointCloud2>(to_point_cloud(header, fed.markers)));
      std::this_thread::sleep_for(std::chrono::microseconds(8333));
    }
  });
  const std::vector<json> events = run_client(
      {"--server", "127.0.0.1", "--command-port", std::to_string(port), "--frames", "30"});
  stop = true;
  publisher.join();

  const std::vector<json> descriptions = of_type(events, "descriptions");
  ASSERT_EQ(descriptions.size(), 1u);
  ASSERT_EQ(descriptions[0]["rigid_bodies"].size(), 1u);
  EXPECT_EQ(descriptions[0]["rigid_bodies"][0]["name"], "wand");
  EXPECT_EQ(descriptions[0]["rigid_bodies"][0]["id"], 12);
  EXPECT_EQ(descriptions[0]["rigid_bodies"][0]["markers"][2]["position"][1].get<float>(), 0.13f);
  const std::vector<json> frames = of_type(events, "frame");
  ASSERT_EQ(frames.size(), 30u);
  for (const json& frame : frames) {
    const int64_t capture = std::stoll(frame["camera_mid_exposure"].get<std::string>());
    const int k = static_cast<int>((capture - kBaseNs + 1000) / 8'333'333);
    const FedFrame fed = fed_frame(k);
    ASSERT_EQ(capture, fed.capture_ns) << frame;
    const int64_t received = std::stoll(frame["camera_data_received"].get<std::string>());
    const int64_t transmit = std::stoll(frame["transmit"].get<std::string>());
    EXPECT_EQ(received - capture, fed.received_ns - fed.capture_ns);  // camera latency
    EXPECT_GE(transmit, received);                                    // software latency
    ASSERT_EQ(frame["rigid_bodies"].size(), 1u);
    const json& body = frame["rigid_bodies"][0];
    EXPECT_EQ(body["id"], 12);
    EXPECT_TRUE(body["tracking_valid"].get<bool>());
    const Vector3f position = fed.wand.translation().cast<float>();
    const Quaternionf q = Eigen::Quaterniond(fed.wand.linear()).cast<float>();
    const float orientation[4] = {q.x(), q.y(), q.z(), q.w()};
    for (int i = 0; i < 3; ++i) EXPECT_EQ(body["position"][i].get<float>(), position[i]);
    for (int i = 0; i < 4; ++i) {
      EXPECT_NEAR(body["orientation"][i].get<float>(), orientation[i], 1e-7f) << frame;
    }
    EXPECT_NEAR(body["mean_error"].get<double>(), 0.0005 / 3, 1e-6);
    // Every marker of the cloud: the wand's three by its id and marker, the stray unlabeled.
    ASSERT_EQ(frame["labeled_markers"].size(), fed.markers.size());
    for (size_t m = 0; m < fed.markers.size(); ++m) {
      const json& marker = frame["labeled_markers"][m];
      for (int i = 0; i < 3; ++i) {
        EXPECT_EQ(marker["position"][i].get<float>(), fed.markers[m].position[i]);
      }
      if (fed.markers[m].body >= 0) {
        EXPECT_EQ(marker["model_id"], 12);
        EXPECT_EQ(marker["marker_id"], fed.markers[m].marker + 1);
      } else {
        EXPECT_TRUE(marker["unlabeled"].get<bool>());
      }
    }
    EXPECT_EQ(frame["unlabeled_markers"].size(), fed.markers.size());  // legacy_markers: all
  }
  host.stop();
}

TEST(NatNetServerPlugin, BadParametersAreNamed) {
  PluginLoader loader;
  for (const auto& [parameters, message] :
       std::vector<std::pair<std::map<std::string, ParameterValue>, std::string>>{
           {{{"up_axis", std::string("x_up")}}, "up_axis: 'x_up'; expected z_up or y_up"},
           {{{"legacy_markers", std::string("some")}},
            "legacy_markers: 'some'; expected none, unlabeled or all"},
           {{{"natnet_version", std::string("2.9")}}, "natnet_version: '2.9'; expected 3.0 to 4.2"},
           {{{"address", std::string("localhost")}}, "address: 'localhost' is not an IPv4 address"},
           {{{"bodies", std::string("/nonexistent/bodies.yaml")}}, "/nonexistent/bodies.yaml"}}) {
    ComponentHost host({.name = "test", .threads = 1, .dds = {.enabled = false}});
    try {
      host.add(*loader.load("natnet_server").factory, {.name = "natnet", .parameters = parameters});
      ADD_FAILURE() << "accepted; expected: " << message;
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
}

TEST(ServerOptions, NameTheFieldThatCannotBeUsed) {
  for (const auto& [options, message] : std::vector<std::pair<ServerOptions, std::string>>{
           {{.address = "localhost"}, "address: 'localhost' is not an IPv4 address"},
           {{.multicast_group = "10.0.0.1"},
            "multicast_group: '10.0.0.1' is not an IPv4 multicast address (224.0.0.0/4)"},
           {{.version = {2, 9}}, "version: 2.9; this server writes NatNet 3.0 to 4.2"},
           {{.max_clients = 0}, "max_clients: 0; every client would be refused"}}) {
    EXPECT_EQ(options.problem(), message);
    EXPECT_THROW(Server{options}, std::invalid_argument);
  }
}

}  // namespace
}  // namespace mocap::natnet
