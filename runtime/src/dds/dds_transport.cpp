#include "dds/dds_transport.hpp"

#include <charconv>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace mocap {

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

}  // namespace mocap
