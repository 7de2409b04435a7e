#include "host/dds_implementations.hpp"

#include <cstdlib>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "dds/cyclonedds/cyclonedds_transport.hpp"
#include "dds/fastdds/fastdds_qos.hpp"
#include "dds/fastdds/fastdds_transport.hpp"

namespace mocap {

namespace {

std::unique_ptr<DdsTransport> make_fastdds(const DdsOptions& options, const std::string& name) {
  return std::make_unique<FastDdsTransport>(options, name);
}
std::unique_ptr<DdsTransport> make_cyclonedds(const DdsOptions& options, const std::string& name) {
  return std::make_unique<CycloneDdsTransport>(options, name);
}
std::optional<std::string> any_governance(const std::filesystem::path&) { return std::nullopt; }

constexpr uint32_t operator|(DdsFeature a, DdsFeature b) { return uint32_t(a) | uint32_t(b); }

// The first is the default.
constexpr DdsImplementation kImplementations[] = {
    {"fastdds", DdsFeature::kSharedMemory | DdsFeature::kDiscoveryServers,
     fastdds_governance_problem, make_fastdds},
    {"cyclonedds", uint32_t(DdsFeature::kSecurityHandshakeWithOthers), any_governance,
     make_cyclonedds},
};

}  // namespace

std::span<const DdsImplementation> dds_implementations() { return kImplementations; }

std::string dds_implementation_names() {
  std::vector<std::string_view> names;
  for (const DdsImplementation& implementation : kImplementations) {
    names.push_back(implementation.name);
  }
  return fmt::format("{}", fmt::join(names, ", "));
}

const DdsImplementation& resolve_dds_implementation(std::string_view configured) {
  std::string_view source = "dds: implementation";
  std::string_view name = configured;
  if (name.empty()) {
    const char* text = std::getenv("MOCAP_DDS_IMPLEMENTATION");
    if (text == nullptr || *text == '\0') return kImplementations[0];
    source = "MOCAP_DDS_IMPLEMENTATION";
    name = text;
  }
  for (const DdsImplementation& implementation : kImplementations) {
    if (implementation.name == name) return implementation;
  }
  throw std::runtime_error(fmt::format("{} '{}' is not a DDS implementation here (available: {})",
                                       source, name, dds_implementation_names()));
}

std::unique_ptr<DdsTransport> make_dds_transport(const DdsOptions& options,
                                                 const std::string& participant_name) {
  return resolve_dds_implementation(options.implementation).make(options, participant_name);
}

}  // namespace mocap
