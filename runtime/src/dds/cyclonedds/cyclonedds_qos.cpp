#include "dds/cyclonedds/cyclonedds_qos.hpp"

#include <dlfcn.h>

#include <chrono>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

#include "dds/dds_options.hpp"
#include "dds/dds_transport.hpp"
#include "dds/writer_backpressure.hpp"

namespace mocap {
namespace fs = std::filesystem;

void to_cyclone_reader_qos(const Qos& qos, dds_qos_t* out) {
  dds_qset_reliability(out,
                       qos.reliability == Reliability::Reliable ? DDS_RELIABILITY_RELIABLE
                                                                : DDS_RELIABILITY_BEST_EFFORT,
                       std::chrono::nanoseconds(kWriteWaitSlice).count());
  dds_qset_durability(out, qos.durability == Durability::TransientLocal
                               ? DDS_DURABILITY_TRANSIENT_LOCAL
                               : DDS_DURABILITY_VOLATILE);
  if (qos.history == History::KeepLast) {
    dds_qset_history(out, DDS_HISTORY_KEEP_LAST, qos.depth);
  } else {
    dds_qset_history(out, DDS_HISTORY_KEEP_ALL, DDS_LENGTH_UNLIMITED);
    // A reader whose history holds `depth` samples rejects what arrives, without acknowledging
    // it: its writers wait for it, as Fast DDS's do.
    dds_qset_resource_limits(out, qos.depth, DDS_LENGTH_UNLIMITED, qos.depth);
  }
  if (qos.durability == Durability::TransientLocal) {
    // What a late-joining subscriber gets: the writer's history, as Fast DDS keeps it.
    dds_qset_durability_service(
        out, 0, qos.history == History::KeepLast ? DDS_HISTORY_KEEP_LAST : DDS_HISTORY_KEEP_ALL,
        qos.depth, DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
  }
  dds_qset_ignorelocal(out, DDS_IGNORELOCAL_PARTICIPANT);
  const dds_data_representation_id_t xcdr1[] = {DDS_DATA_REPRESENTATION_XCDR1};
  dds_qset_data_representation(out, 1, xcdr1);
}

void to_cyclone_writer_qos(const Qos& qos, dds_qos_t* out) {
  to_cyclone_reader_qos(qos, out);
  if (qos.reliability == Reliability::Reliable && qos.durability == Durability::Volatile) {
    // On the wire as Fast DDS processes put theirs (fastdds_qos.cpp, to_writer_qos, says why):
    // transient-local, keeping one sample, with the mark that says it is volatile. So every
    // subscriber, on either implementation, sees the same publisher whatever carries it: a
    // latched one matches it and takes nothing from it, and says so.
    dds_qset_durability(out, DDS_DURABILITY_TRANSIENT_LOCAL);
    dds_qset_durability_service(out, 0, DDS_HISTORY_KEEP_LAST, 1, DDS_LENGTH_UNLIMITED,
                                DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
    dds_qset_userdata(out, kVolatileWriterMark.data(), kVolatileWriterMark.size());
  }
}

Qos qos_from_cyclone(const dds_qos_t* qos) {
  Qos out;
  dds_reliability_kind_t reliability = DDS_RELIABILITY_BEST_EFFORT;
  dds_qget_reliability(qos, &reliability, nullptr);
  out.reliability =
      reliability == DDS_RELIABILITY_RELIABLE ? Reliability::Reliable : Reliability::BestEffort;
  dds_durability_kind_t durability = DDS_DURABILITY_VOLATILE;
  dds_qget_durability(qos, &durability);
  Durability announced =
      durability == DDS_DURABILITY_VOLATILE ? Durability::Volatile : Durability::TransientLocal;
  void* data = nullptr;
  size_t size = 0;
  std::vector<uint8_t> user_data;
  if (dds_qget_userdata(qos, &data, &size) && data != nullptr) {
    user_data.assign(static_cast<uint8_t*>(data), static_cast<uint8_t*>(data) + size);
  }
  dds_free(data);
  out.durability = offered_durability(announced, user_data);
  return out;
}

namespace {

// Where Debian keeps Cyclone's DDS Security plugins: beside libddsc, in libddsc0debian/.
fs::path security_plugin(const char* name) {
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&dds_create_participant), &info) == 0 ||
      info.dli_fname == nullptr) {
    return fmt::format("lib{}.so", name);
  }
  fs::path folder = fs::path(info.dli_fname).parent_path();
  for (const fs::path& candidate : {folder / "libddsc0debian" / fmt::format("lib{}.so", name),
                                    folder / fmt::format("lib{}.so", name)}) {
    if (fs::exists(candidate)) return candidate;
  }
  return fmt::format("lib{}.so", name);
}

}  // namespace

std::string domain_configuration(const DdsOptions& options) {
  std::string security;
  if (!options.security_directory.empty()) {
    fs::path directory = fs::absolute(options.security_directory).lexically_normal();
    if (auto problem = check_security(directory, options.security_identity)) {
      throw std::runtime_error(fmt::format("DDS Security: {}", problem->message));
    }
    SecurityFiles files = security_files(directory, options.security_identity);
    auto uri = [](const fs::path& path) { return "file:" + path.string(); };
    security = fmt::format(
        "<Security>"
        "<Authentication><Library path=\"{}\" initFunction=\"init_authentication\" "
        "finalizeFunction=\"finalize_authentication\"/>"
        "<IdentityCA>{}</IdentityCA><IdentityCertificate>{}</IdentityCertificate>"
        "<PrivateKey>{}</PrivateKey></Authentication>"
        "<AccessControl><Library path=\"{}\" initFunction=\"init_access_control\" "
        "finalizeFunction=\"finalize_access_control\"/>"
        "<PermissionsCA>{}</PermissionsCA><Governance>{}</Governance>"
        "<Permissions>{}</Permissions></AccessControl>"
        "<Cryptographic><Library path=\"{}\" initFunction=\"init_crypto\" "
        "finalizeFunction=\"finalize_crypto\"/></Cryptographic>"
        "</Security>",
        security_plugin("dds_security_auth").string(), uri(files.ca), uri(files.certificate),
        uri(files.private_key), security_plugin("dds_security_ac").string(), uri(files.ca),
        uri(files.governance), uri(files.permissions),
        security_plugin("dds_security_crypto").string());
  }
  // A crashed peer is forgotten after 5 s, as with Fast DDS (fastdds_qos.cpp says why).
  // A Fast DDS writer sends a large sample's fragments in one burst, without Cyclone's own
  // pacing: with Cyclone's 1 MB socket buffer a 1280x720 image overflowed it, and the repairs
  // cut the rate from Fast DDS to Cyclone eightfold (transport_bench). Both implementations ask
  // for kUdpSocketBufferBytes; the kernel caps the request at net.core.rmem_max.
  // Fragments as large as Fast DDS's (64 KB datagrams, which IP fragments to the link's MTU)
  // instead of Cyclone's 1344 bytes in 14720-byte messages: a 1280x720 image over UDP from a
  // Cyclone writer went from 0.75 ms to 0.28 ms on loopback (bench/image_hop_bench).
  return fmt::format(
      "<CycloneDDS><Domain Id=\"any\"><General><MaxMessageSize>65500B</MaxMessageSize>"
      "<FragmentSize>65000B</FragmentSize></General>"
      "<Discovery><LeaseDuration>5 s</LeaseDuration></Discovery>"
      "<Internal><SocketReceiveBufferSize min=\"default\" max=\"{}B\"/></Internal>"
      "{}</Domain></CycloneDDS>",
      kUdpSocketBufferBytes, security);
}

}  // namespace mocap
