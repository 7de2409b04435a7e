#include "dds_transport.hpp"

#include <charconv>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

#include "cyclonedds_transport.hpp"
#include "fastdds_qos.hpp"
#include "fastdds_transport.hpp"

namespace mocap {

std::string resolve_dds_implementation(std::string_view configured) {
  std::string_view source = "dds: implementation";
  std::string_view name = configured;
  if (name.empty()) {
    const char* text = std::getenv("MOCAP_DDS_IMPLEMENTATION");
    if (text == nullptr || *text == '\0') return "fastdds";
    source = "MOCAP_DDS_IMPLEMENTATION";
    name = text;
  }
  if (name != "fastdds" && name != "cyclonedds") {
    throw std::runtime_error(fmt::format("{} '{}' is not a DDS implementation here (available: {})",
                                         source, name, kDdsImplementations));
  }
  return std::string(name);
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

std::optional<std::string> governance_problem(std::string_view implementation,
                                              const std::filesystem::path& directory) {
  if (implementation != "fastdds") return std::nullopt;
  return fastdds_governance_problem(security_files(directory, "").governance);
}

std::unique_ptr<DdsTransport> make_dds_transport(const DdsOptions& options,
                                                 const std::string& participant_name) {
  if (resolve_dds_implementation(options.implementation) == "cyclonedds") {
    return std::make_unique<CycloneDdsTransport>(options, participant_name);
  }
  return std::make_unique<FastDdsTransport>(options, participant_name);
}

}  // namespace mocap
