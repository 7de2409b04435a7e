#include "outputs/natnet_server/natnet_server.hpp"

#include <arpa/inet.h>
#include <ifaddrs.h>
#include <net/if.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

#include <fmt/format.h>

namespace mocap::natnet {
namespace {

using SteadyClock = std::chrono::steady_clock;

constexpr std::chrono::milliseconds kPollPeriod{100};
// Datagrams read per wake-up at most, so that one flooding source cannot hold the thread.
constexpr int kMaxReadsPerWake = 256;
// Source addresses whose reply rate is kept; past this, the longest idle is forgotten.
constexpr size_t kMaxRateEntries = 4096;
// All sources together may draw this many times one source's rate.
constexpr double kGlobalRateFactor = 20;
// The frames over which FrameRate is measured.
constexpr size_t kRateWindow = 30;

std::string errno_text() { return std::strerror(errno); }

struct Endpoint {
  in_addr_t address = 0;
  in_port_t port = 0;
  auto operator<=>(const Endpoint&) const = default;
};

Endpoint endpoint_of(const sockaddr_in& address) {
  return {address.sin_addr.s_addr, address.sin_port};
}

sockaddr_in socket_address(const Endpoint& endpoint) {
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = endpoint.address;
  address.sin_port = endpoint.port;
  return address;
}

struct Client {
  Version version;
  SteadyClock::time_point last_heard;
  bool bitstream_changed = false;  // its next frame says so
};

// A token bucket: `rate` a second, `burst` at most.
struct Bucket {
  double tokens = 0;
  SteadyClock::time_point refilled;

  bool take(double rate, double burst, SteadyClock::time_point now) {
    tokens = std::min(burst, tokens + rate * std::chrono::duration<double>(now - refilled).count());
    refilled = now;
    if (tokens < 1) return false;
    tokens -= 1;
    return true;
  }
};

// The interface index of `name`, or of the interface that holds `address`; 0: none found.
unsigned interface_for(const std::string& name, in_addr address) {
  if (!name.empty()) return if_nametoindex(name.c_str());
  if ((ntohl(address.s_addr) >> 24) == 127) return if_nametoindex("lo");
  if (address.s_addr == htonl(INADDR_ANY)) return 0;
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) return 0;
  unsigned index = 0;
  for (ifaddrs* entry = list; entry; entry = entry->ifa_next) {
    if (entry->ifa_addr && entry->ifa_addr->sa_family == AF_INET &&
        reinterpret_cast<sockaddr_in*>(entry->ifa_addr)->sin_addr.s_addr == address.s_addr) {
      index = if_nametoindex(entry->ifa_name);
      break;
    }
  }
  freeifaddrs(list);
  return index;
}

}  // namespace

struct Server::Impl {
  ServerOptions options;
  int command_fd = -1, data_fd = -1, wake_fd = -1;
  uint16_t command_port = 0, data_port = 0;
  bool loopback = false;
  sockaddr_in group{};

  mutable std::mutex mutex;
  std::map<Endpoint, Client> clients;
  std::map<in_addr_t, Bucket> reply_rates;
  Bucket global_rate;
  Descriptions descriptions;
  bool models_changed = true;
  int32_t frame_number = 0;
  FrameOfData last_frame;
  std::deque<double> frame_stamps_s;
  ServerStats stats;

  std::atomic<bool> stopping{false};
  std::thread thread;

  ~Impl() {
    for (int fd : {command_fd, data_fd, wake_fd}) {
      if (fd >= 0) ::close(fd);
    }
  }

  void open(const ServerOptions& requested) {
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(requested.command_port);
    inet_pton(AF_INET, requested.address.c_str(), &address.sin_addr);  // checked by problem()
    loopback = (ntohl(address.sin_addr.s_addr) >> 24) == 127;
    command_fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (::bind(command_fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
      throw std::runtime_error(fmt::format("address/command_port: cannot bind UDP {}:{}: {}",
                                           requested.address, requested.command_port,
                                           errno_text()));
    }
    socklen_t size = sizeof address;
    getsockname(command_fd, reinterpret_cast<sockaddr*>(&address), &size);
    command_port = ntohs(address.sin_port);
    // Frames go out whole or not at all: a large send buffer rather than a short wait; and room
    // for a burst of requests while the thread reads them.
    const int buffer = 4 << 20;
    setsockopt(command_fd, SOL_SOCKET, SO_SNDBUF, &buffer, sizeof buffer);
    setsockopt(command_fd, SOL_SOCKET, SO_RCVBUF, &buffer, sizeof buffer);
    wake_fd = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
    open_data(requested, address.sin_addr);
    if (requested.multicast) open_multicast(requested, address.sin_addr);
  }

  // Frames leave from the data port, unicast as multicast, as a Motive host sends them: OptiTrack's
  // NatNetLib takes what comes from the server's command port for answers and passes frames on
  // only from its data port. Shared (SO_REUSEADDR), as multicast clients on this host bind it too.
  void open_data(const ServerOptions& requested, in_addr local) {
    data_fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    const int on = 1;
    setsockopt(data_fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr = local;
    address.sin_port = htons(requested.data_port);
    if (::bind(data_fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
      throw std::runtime_error(fmt::format("address/data_port: cannot bind UDP {}:{}: {}",
                                           requested.address, requested.data_port, errno_text()));
    }
    socklen_t size = sizeof address;
    getsockname(data_fd, reinterpret_cast<sockaddr*>(&address), &size);
    data_port = ntohs(address.sin_port);
    const int buffer = 4 << 20;
    setsockopt(data_fd, SOL_SOCKET, SO_SNDBUF, &buffer, sizeof buffer);
  }

  void open_multicast(const ServerOptions& requested, in_addr local) {
    group.sin_family = AF_INET;
    group.sin_port = htons(data_port);
    inet_pton(AF_INET, requested.multicast_group.c_str(), &group.sin_addr);
    const unsigned index = interface_for(requested.multicast_interface, local);
    if (!requested.multicast_interface.empty() && index == 0) {
      throw std::runtime_error(fmt::format("multicast_interface: no interface '{}' on this host",
                                           requested.multicast_interface));
    }
    ip_mreqn interface {};
    interface.imr_ifindex = static_cast<int>(index);
    const unsigned char ttl = 1, loop = 1;
    if (setsockopt(data_fd, IPPROTO_IP, IP_MULTICAST_IF, &interface, sizeof interface) != 0 ||
        setsockopt(data_fd, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl) != 0 ||
        setsockopt(data_fd, IPPROTO_IP, IP_MULTICAST_LOOP, &loop, sizeof loop) != 0) {
      throw std::runtime_error(fmt::format("multicast_interface: cannot send multicast on '{}': {}",
                                           requested.multicast_interface, errno_text()));
    }
  }

  void wake() const {
    const uint64_t one = 1;
    [[maybe_unused]] auto written = ::write(wake_fd, &one, sizeof one);
  }

  // --- under the mutex -----------------------------------------------------------------------

  void send_to(const Endpoint& to, const std::string& packet) {
    const sockaddr_in address = socket_address(to);
    ::sendto(command_fd, packet.data(), packet.size(), MSG_DONTWAIT | MSG_NOSIGNAL,
             reinterpret_cast<const sockaddr*>(&address), sizeof address);
  }

  // Whether a reply to `to` may go now: its source's rate and everyone's together.
  bool may_reply(const Endpoint& to, SteadyClock::time_point now) {
    auto found = reply_rates.find(to.address);
    if (found == reply_rates.end()) {
      if (reply_rates.size() >= kMaxRateEntries) {
        reply_rates.erase(std::min_element(
            reply_rates.begin(), reply_rates.end(),
            [](const auto& a, const auto& b) { return a.second.refilled < b.second.refilled; }));
      }
      found = reply_rates.emplace(to.address, Bucket{options.reply_burst, now}).first;
    }
    if (!found->second.take(options.replies_per_s, options.reply_burst, now) ||
        !global_rate.take(options.replies_per_s * kGlobalRateFactor,
                          options.reply_burst * kGlobalRateFactor, now)) {
      ++stats.replies_limited;
      return false;
    }
    return true;
  }

  void reply(const Endpoint& to, const std::string& packet, SteadyClock::time_point now) {
    if (may_reply(to, now)) send_to(to, packet);
  }

  Version version_of(const Endpoint& from) const {
    auto client = clients.find(from);
    return client == clients.end() ? options.version : client->second.version;
  }

  ServerDescription description_for(Version version) const {
    ServerDescription server;
    server.application = options.application;
    server.natnet = version;
    server.data_port = data_port;
    server.multicast = options.multicast;
    if (options.multicast) std::memcpy(server.multicast_group, &group.sin_addr, 4);
    return server;
  }

  void handle(const Endpoint& from, const Request& request, SteadyClock::time_point now) {
    ++stats.requests;
    if (auto client = clients.find(from); client != clients.end()) {
      client->second.last_heard = now;
    }
    switch (request.id) {
      case kConnect:
        return connect(from, request, now);
      case kRequestModelDef:
        return reply(from, encode_descriptions(descriptions, version_of(from)), now);
      case kRequestFrameOfData:
        if (frame_number > 0) {
          std::string packet = encode_frame(last_frame, version_of(from));
          set_transmit_stamp(packet, version_of(from), now_ticks());
          reply(from, packet, now);
        }
        return;
      case kRequest:
        return command(from, command_text(request), now);
      case kKeepAlive:
        return;
      case kDisconnect:
        if (clients.erase(from) > 0) ++stats.clients_disconnected;
        return;
      case kEchoRequest: {
        uint64_t stamp = 0;
        std::memcpy(&stamp, request.payload.data(), std::min<size_t>(8, request.payload.size()));
        return reply(from, encode_echo_response(stamp, now_ticks()), now);
      }
      default:
        ++stats.unrecognized;
        return reply(from, encode_unrecognized_request(), now);
    }
  }

  // A client is added only when its answer may go: a forged NAT_CONNECT registers a stream to its
  // source no more often than that source may be answered.
  void connect(const Endpoint& from, const Request& request, SteadyClock::time_point now) {
    if (!may_reply(from, now)) return;
    Version version = options.version;
    if (const std::optional<Version> asked = requested_version(request);
        asked && asked->supported() && !options.multicast) {
      version = *asked;
    }
    if (!options.multicast) {
      auto client = clients.find(from);
      if (client == clients.end()) {
        if (clients.size() >= options.max_clients) {
          ++stats.clients_refused;
          return send_to(from, encode_message_string(fmt::format(
                                   "refused: this server serves {} unicast clients at most",
                                   options.max_clients)));
        }
        ++stats.clients_connected;
        client = clients.emplace(from, Client{version, now}).first;
      }
      client->second.version = version;
    }
    send_to(from, encode_server_info(description_for(version)));
  }

  void command(const Endpoint& from, const std::string& text, SteadyClock::time_point now) {
    const size_t comma = text.find(',');
    const std::string name = text.substr(0, comma);
    if (name == "Bitstream") {
      if (comma == std::string::npos) {
        const Version version = version_of(from);
        return reply(from,
                     encode_response(fmt::format("Bitstream,{}.{}", version.major, version.minor)),
                     now);
      }
      const std::optional<Version> asked = parse_version(text.substr(comma + 1));
      auto client = clients.find(from);
      if (!asked || !asked->supported() || options.multicast || client == clients.end()) {
        return reply(from, encode_response(int32_t{1}), now);
      }
      client->second.bitstream_changed = !(client->second.version.written() == asked->written());
      client->second.version = *asked;
      return reply(from, encode_response(int32_t{0}), now);
    }
    if (name == "FrameRate") return reply(from, encode_response(frame_rate()), now);
    if (name == "UnitsToMillimeters") return reply(from, encode_response(1000.0f), now);
    if (name == "CurrentMode") return reply(from, encode_response(int32_t{0}), now);
    ++stats.unrecognized;
    reply(from, encode_unrecognized_request(), now);
  }

  float frame_rate() const {
    if (frame_stamps_s.size() < 2) return 0;
    const double span = frame_stamps_s.back() - frame_stamps_s.front();
    return span > 0 ? static_cast<float>((frame_stamps_s.size() - 1) / span) : 0;
  }

  // --- the thread ----------------------------------------------------------------------------

  void run() {
    std::vector<char> buffer(1 << 16);
    while (!stopping) {
      pollfd fds[2] = {{command_fd, POLLIN, 0}, {wake_fd, POLLIN, 0}};
      ::poll(fds, 2, static_cast<int>(kPollPeriod.count()));
      if (fds[1].revents & POLLIN) {
        uint64_t count = 0;
        [[maybe_unused]] auto read = ::read(wake_fd, &count, sizeof count);
      }
      for (int reads = 0; reads < kMaxReadsPerWake && !stopping; ++reads) {
        sockaddr_in source{};
        socklen_t length = sizeof source;
        const ssize_t n = ::recvfrom(command_fd, buffer.data(), buffer.size(), 0,
                                     reinterpret_cast<sockaddr*>(&source), &length);
        if (n < 0) break;
        received(endpoint_of(source), std::string_view(buffer.data(), static_cast<size_t>(n)));
      }
      forget_silent_clients();
    }
  }

  void received(const Endpoint& from, std::string_view datagram) {
    const SteadyClock::time_point now = SteadyClock::now();
    std::lock_guard lock(mutex);
    std::string problem;
    const std::optional<Request> request = parse_request(datagram, &problem);
    if (!request) {
      ++stats.malformed;
      if (clients.erase(from) > 0) ++stats.clients_dropped_malformed;
      return;
    }
    handle(from, *request, now);
  }

  void forget_silent_clients() {
    const auto now = SteadyClock::now();
    const auto timeout = std::chrono::duration<double>(options.client_timeout_s);
    std::lock_guard lock(mutex);
    std::erase_if(clients, [&](const auto& entry) {
      if (now - entry.second.last_heard < timeout) return false;
      ++stats.clients_timed_out;
      return true;
    });
  }

  // --- frames --------------------------------------------------------------------------------

  // The frame in `version`, cut to fit a datagram.
  std::string fitted_frame(FrameOfData& frame, Version version) {
    std::string packet = encode_frame(frame, version);
    if (packet.size() - kHeaderSize <= kMaxPayload) return packet;
    ++stats.frames_too_large;
    while (packet.size() - kHeaderSize > kMaxPayload) {
      const size_t over = packet.size() - kHeaderSize - kMaxPayload;
      if (!frame.labeled_markers.empty()) {
        const size_t drop = std::min(frame.labeled_markers.size(), over / 24 + 1);
        frame.labeled_markers.resize(frame.labeled_markers.size() - drop);
      } else if (!frame.other_markers.empty()) {
        const size_t drop = std::min(frame.other_markers.size(), over / 12 + 1);
        frame.other_markers.resize(frame.other_markers.size() - drop);
      } else {
        frame.marker_sets.clear();
      }
      packet = encode_frame(frame, version);
    }
    return packet;
  }

  void send_datagram(const std::string& packet, const sockaddr_in& to, int fd) {
    const ssize_t sent = ::sendto(fd, packet.data(), packet.size(), MSG_DONTWAIT | MSG_NOSIGNAL,
                                  reinterpret_cast<const sockaddr*>(&to), sizeof to);
    if (sent == static_cast<ssize_t>(packet.size())) {
      ++stats.datagrams_sent;
    } else {
      ++stats.datagrams_dropped;
    }
  }
};

std::optional<std::string> ServerOptions::problem() const {
  in_addr parsed{};
  if (inet_pton(AF_INET, address.c_str(), &parsed) != 1) {
    return fmt::format("address: '{}' is not an IPv4 address", address);
  }
  if (inet_pton(AF_INET, multicast_group.c_str(), &parsed) != 1 ||
      (ntohl(parsed.s_addr) >> 28) != 0xE) {
    return fmt::format("multicast_group: '{}' is not an IPv4 multicast address (224.0.0.0/4)",
                       multicast_group);
  }
  if (!version.supported()) {
    return fmt::format("version: {}.{}; this server writes NatNet 3.0 to 4.2", version.major,
                       version.minor);
  }
  if (max_clients == 0) return "max_clients: 0; every client would be refused";
  if (!(client_timeout_s > 0)) return "client_timeout_s: must be above 0";
  if (!(replies_per_s > 0) || !(reply_burst >= 1)) {
    return "replies_per_s/reply_burst: a client needs at least one reply";
  }
  return std::nullopt;
}

Server::Server(ServerOptions options) {
  if (auto problem = options.problem()) {
    throw std::invalid_argument("natnet::ServerOptions::" + *problem);
  }
  impl_ = std::make_unique<Impl>();
  impl_->options = options;
  impl_->global_rate = {options.reply_burst * kGlobalRateFactor, SteadyClock::now()};
  impl_->open(options);
  impl_->thread = std::thread([impl = impl_.get()] { impl->run(); });
}

Server::~Server() {
  impl_->stopping = true;
  impl_->wake();
  impl_->thread.join();
}

uint16_t Server::command_port() const { return impl_->command_port; }

uint16_t Server::data_port() const { return impl_->data_port; }

bool Server::loopback_only() const { return impl_->loopback; }

void Server::set_descriptions(Descriptions descriptions) {
  std::lock_guard lock(impl_->mutex);
  impl_->descriptions = std::move(descriptions);
  impl_->models_changed = true;
}

void Server::send_frame(FrameOfData frame) {
  Impl& s = *impl_;
  std::lock_guard lock(s.mutex);
  ++s.stats.frames;
  frame.frame_number = ++s.frame_number;
  frame.tracked_models_changed = std::exchange(s.models_changed, false);
  s.frame_stamps_s.push_back(frame.timestamp_s);
  if (s.frame_stamps_s.size() > kRateWindow) s.frame_stamps_s.pop_front();
  // One encoding per version in use; each copy's transmit stamp set just before it leaves.
  std::map<std::pair<uint8_t, uint8_t>, std::string> encoded;
  auto packet_for = [&](Version version) -> std::string& {
    const Version written = version.written();
    auto [found, added] = encoded.try_emplace({written.major, written.minor});
    if (added) found->second = s.fitted_frame(frame, written);
    return found->second;
  };
  if (s.options.multicast) {
    std::string& packet = packet_for(s.options.version);
    set_transmit_stamp(packet, s.options.version, now_ticks());
    s.send_datagram(packet, s.group, s.data_fd);
  } else {
    for (auto& [endpoint, client] : s.clients) {
      std::string& packet = packet_for(client.version);
      set_bitstream_changed(packet, std::exchange(client.bitstream_changed, false));
      set_transmit_stamp(packet, client.version, now_ticks());
      s.send_datagram(packet, socket_address(endpoint), s.data_fd);
    }
  }
  s.last_frame = std::move(frame);
}

size_t Server::clients() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->clients.size();
}

ServerStats Server::stats() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->stats;
}

uint64_t Server::now_ticks() {
  return static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                   std::chrono::system_clock::now().time_since_epoch())
                                   .count());
}

}  // namespace mocap::natnet
