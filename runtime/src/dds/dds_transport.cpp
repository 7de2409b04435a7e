#include "dds/dds_transport.hpp"

#include <charconv>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>

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

// The first is the default.
constexpr DdsImplementation kImplementations[] = {
    {"fastdds", true, fastdds_governance_problem, make_fastdds},
    {"cyclonedds", false, any_governance, make_cyclonedds},
};

}  // namespace

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

std::optional<std::string> udp_buffer_problem(const std::filesystem::path& sysctl_directory) {
  std::vector<std::string> capped;
  for (const char* name : {"rmem_max", "wmem_max"}) {
    std::ifstream file(sysctl_directory / name);
    uint64_t bytes = 0;
    if (file >> bytes && bytes < kUdpSocketBufferBytes) {
      capped.push_back(fmt::format("net.core.{} is {} bytes", name, bytes));
    }
  }
  if (capped.empty()) return std::nullopt;
  return fmt::format(
      "{}: UDP socket buffers are capped there, and large samples (camera images) between "
      "hosts wait for repairs; to lift the cap: sysctl -w net.core.rmem_max={} "
      "net.core.wmem_max={}",
      fmt::join(capped, " and "), kUdpSocketBufferBytes, kUdpSocketBufferBytes);
}

int resolve_domain_id(int configured) {
  const char* text = std::getenv("MOCAP_DOMAIN_ID");
  if (text == nullptr || *text == '\0') return configured;
  int value = -1;
  auto [end, error] = std::from_chars(text, text + std::strlen(text), value);
  if (error != std::errc() || *end != '\0' || value < 0 || value > 232) {
    throw std::runtime_error(
        fmt::format("MOCAP_DOMAIN_ID='{}' is not a DDS domain id (an integer 0..232)", text));
  }
  return value;
}

std::unique_ptr<DdsTransport> make_dds_transport(const DdsOptions& options,
                                                 const std::string& participant_name) {
  return resolve_dds_implementation(options.implementation).make(options, participant_name);
}

}  // namespace mocap
