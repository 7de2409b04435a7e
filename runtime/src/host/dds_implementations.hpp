// The DDS implementations this runtime carries, what each can do, and the choice among them:
// the one table the host, the launcher and the tools ask (runtime/README.md says how to add
// one). It sits above the implementations, which know nothing of each other.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include <mocap/component_host.hpp>

#include "dds/dds_transport.hpp"

namespace mocap {

// What an implementation can do beyond the wire every one of them shares; the launcher and the
// host ask the table (as ROS 2 asks rmw_feature_supported) instead of comparing names.
enum class DdsFeature : uint32_t {
  // Takes DdsOptions::shared_memory: samples between processes of one host through shared
  // memory. Without it, it talks UDP only.
  kSharedMemory = 1u << 0,
  // Takes DdsOptions::discovery_servers. Without it, a launch file that names servers for a
  // group on it is refused.
  kDiscoveryServers = 1u << 1,
  // Authenticates a participant of another implementation whichever side starts DDS Security's
  // handshake. Without it (Fast DDS 2.9 starting it towards Cyclone DDS 0.10 fails), groups of
  // one launch file that share an identity are refused on it beside another implementation.
  kSecurityHandshakeWithOthers = 1u << 2,
};

// A DDS implementation this runtime carries, and what it can do. Adding one: a folder under
// dds/ with its DdsTransport, its line in the table of dds_implementations.cpp and its name in
// runtime/CMakeLists.txt's MOCAP_DDS_IMPLEMENTATIONS (runtime/README.md).
struct DdsImplementation {
  std::string_view name;  // as DdsOptions::implementation and MOCAP_DDS_IMPLEMENTATION say it
  uint32_t features;      // DdsFeature bits
  // Why it cannot take the signed governance document `governance`, or nullopt.
  std::optional<std::string> (*governance_problem)(const std::filesystem::path& governance);
  std::unique_ptr<DdsTransport> (*make)(const DdsOptions& options,
                                        const std::string& participant_name);

  bool supports(DdsFeature feature) const { return (features & uint32_t(feature)) != 0; }
};

// Every implementation this build carries; the first is the default.
std::span<const DdsImplementation> dds_implementations();

// The names DdsOptions::implementation takes, for messages: "fastdds, cyclonedds".
std::string dds_implementation_names();

// `configured` when set, else MOCAP_DDS_IMPLEMENTATION when set, else the first of the table
// (Fast DDS). Throws std::runtime_error naming the source of an unknown name and listing the
// known ones.
const DdsImplementation& resolve_dds_implementation(std::string_view configured);

// A participant named `participant_name` on the implementation `options` (and the environment)
// choose. Throws std::runtime_error when it cannot be created.
std::unique_ptr<DdsTransport> make_dds_transport(const DdsOptions& options,
                                                 const std::string& participant_name);

}  // namespace mocap
