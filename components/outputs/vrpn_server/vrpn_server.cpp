#include "outputs/vrpn_server/vrpn_server.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
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
#include <vector>

#include <fmt/format.h>

namespace mocap::vrpn {
namespace {

// Our own numbering of the types we send.
constexpr int32_t kPosQuat = 0;
constexpr int32_t kVelocity = 1;
constexpr int32_t kPong = 2;

constexpr std::chrono::milliseconds kPollPeriod{200};
// Connections made back to one UDP request source within the window, at most.
constexpr size_t kMaxConnectBacksPerSource = 4;
constexpr std::chrono::seconds kConnectBackWindow{10};

std::string errno_text() { return std::strerror(errno); }

void set_non_blocking(int fd) { fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK); }

Message stamped(Message message, int64_t stamp_ns) {
  message.seconds = static_cast<uint32_t>(stamp_ns / 1'000'000'000);
  message.microseconds = static_cast<uint32_t>(stamp_ns % 1'000'000'000 / 1000);
  return message;
}

int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// A UDP connection request, "ADDRESS PORT" with a NUL or not: VRPN's client sends its IPv4
// address and the TCP port it listens on, above 1023.
std::optional<sockaddr_in> parse_request(std::string_view text) {
  if (const size_t nul = text.find('\0'); nul != std::string_view::npos) text = text.substr(0, nul);
  const size_t space = text.find(' ');
  if (space == std::string_view::npos || space == 0) return std::nullopt;
  const std::string host(text.substr(0, space));
  int port = 0;
  for (char c : text.substr(space + 1)) {
    if (c == '\n' || c == '\r') break;
    if (c < '0' || c > '9' || port > 65535) return std::nullopt;
    port = port * 10 + (c - '0');
  }
  if (port < 1024 || port > 65535) return std::nullopt;
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  if (inet_pton(AF_INET, host.c_str(), &address.sin_addr) != 1) return std::nullopt;
  return address;
}

struct Client {
  enum class State { Connecting, AwaitingCookie, Connected };

  int fd = -1;
  State state = State::AwaitingCookie;
  std::string out;  // queued bytes, from `sent` on
  size_t sent = 0;
  std::string cookie_in;
  MessageReader reader;
  std::map<int32_t, std::string> their_types, their_senders;
  bool closing = false;
  // A connection this server made back to a UDP request's source (that address), or 0.
  in_addr_t connected_back_to = 0;

  size_t queued() const { return out.size() - sent; }
};

}  // namespace

struct TrackerServer::Impl {
  TrackerServerOptions options;
  int tcp_fd = -1, udp_fd = -1, wake_fd = -1;
  uint16_t port = 0;
  bool loopback = false;

  mutable std::mutex mutex;
  std::vector<std::unique_ptr<Client>> clients;
  std::map<std::string, int32_t> tracker_ids;
  std::vector<std::string> tracker_names;        // by id
  std::map<int32_t, std::string> latest_report;  // id -> its last Pos_Quat and Velocity
  uint32_t sequence = 0;
  TrackerServerStats stats;
  // Connections made back to each UDP request source within kConnectBackWindow.
  std::map<in_addr_t, std::deque<std::chrono::steady_clock::time_point>> connect_backs;

  std::atomic<bool> stopping{false};
  std::thread thread;

  ~Impl() {
    for (int fd : {tcp_fd, udp_fd, wake_fd}) {
      if (fd >= 0) ::close(fd);
    }
    for (auto& client : clients) ::close(client->fd);
  }

  void listen(const TrackerServerOptions& requested) {
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(requested.port);
    const std::string where = fmt::format("{}:{}", requested.address, requested.port);
    inet_pton(AF_INET, requested.address.c_str(), &address.sin_addr);  // checked by problem()
    loopback = (ntohl(address.sin_addr.s_addr) >> 24) == 127;
    tcp_fd = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    const int on = 1;
    setsockopt(tcp_fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
    if (::bind(tcp_fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
        ::listen(tcp_fd, 16) != 0) {
      throw std::runtime_error("address/port: cannot listen on TCP " + where + ": " + errno_text());
    }
    socklen_t size = sizeof address;
    getsockname(tcp_fd, reinterpret_cast<sockaddr*>(&address), &size);
    port = ntohs(address.sin_port);
    udp_fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (::bind(udp_fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
      throw std::runtime_error(fmt::format("address/port: cannot bind UDP {}:{}: {}",
                                           requested.address, port, errno_text()));
    }
    wake_fd = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  }

  void wake() const {
    const uint64_t one = 1;
    [[maybe_unused]] auto written = ::write(wake_fd, &one, sizeof one);
  }

  // --- under the mutex -----------------------------------------------------------------------

  void queue(Client& client, const std::string& bytes) {
    if (client.closing) return;
    client.out += bytes;
    if (client.queued() > options.max_queued_bytes) {
      client.closing = true;
      ++stats.clients_too_slow;
    }
  }

  std::string next_encoded(Message message) {
    message.sequence = sequence++;
    return encode(message);
  }

  void greet(Client& client) {
    client.state = Client::State::Connected;
    ++stats.clients_connected;
    const int64_t now = now_ns();
    std::string bytes;
    for (const auto& [id, name] :
         {std::pair{kPosQuat, kPosQuatType}, {kVelocity, kVelocityType}, {kPong, kPongType}}) {
      bytes += next_encoded(stamped(description(kTypeDescription, id, name), now));
    }
    for (size_t id = 0; id < tracker_names.size(); ++id) {
      bytes += next_encoded(stamped(
          description(kSenderDescription, static_cast<int32_t>(id), tracker_names[id]), now));
    }
    for (const auto& [id, report] : latest_report) bytes += report;
    queue(client, bytes);
  }

  void received(Client& client, std::string_view bytes) {
    if (client.state == Client::State::AwaitingCookie) {
      const size_t take = std::min(bytes.size(), kCookieSize - client.cookie_in.size());
      client.cookie_in.append(bytes.substr(0, take));
      bytes.remove_prefix(take);
      if (client.cookie_in.size() < kCookieSize) return;
      if (check_cookie(client.cookie_in) == CookieCheck::NotVrpn) {
        client.closing = true;
        ++stats.clients_refused;
        return;
      }
      greet(client);
    }
    client.reader.feed(bytes);
    while (auto message = client.reader.next()) handle(client, *message);
    if (!client.reader.error().empty()) {
      client.closing = true;
      ++stats.clients_refused;
    }
  }

  void handle(Client& client, const Message& message) {
    if (message.type == kTypeDescription || message.type == kSenderDescription) {
      if (auto name = described_name(message)) {
        (message.type == kTypeDescription ? client.their_types
                                          : client.their_senders)[message.sender] = *name;
      }
      return;
    }
    if (message.type < 0) return;  // UDP port, logging: nothing for a TCP-only server
    auto type = client.their_types.find(message.type);
    if (type == client.their_types.end() || type->second != kPingType) return;
    // A ping to one of our trackers: the pong comes from it.
    auto sender = client.their_senders.find(message.sender);
    if (sender == client.their_senders.end()) return;
    auto ours = tracker_ids.find(sender->second);
    if (ours == tracker_ids.end()) return;
    Message pong;
    pong.sender = ours->second;
    pong.type = kPong;
    queue(client, next_encoded(stamped(pong, now_ns())));
    ++stats.pongs;
  }

  // --- the thread ----------------------------------------------------------------------------

  void run() {
    std::vector<pollfd> fds;
    std::vector<Client*> polled;
    char buffer[1 << 16];
    while (!stopping) {
      fds.assign({{tcp_fd, POLLIN, 0}, {udp_fd, POLLIN, 0}, {wake_fd, POLLIN, 0}});
      polled.clear();
      {
        std::lock_guard lock(mutex);
        for (auto& client : clients) {
          short events = POLLIN;
          if (client->state == Client::State::Connecting) events = POLLOUT;
          if (client->queued() > 0) events |= POLLOUT;
          fds.push_back({client->fd, events, 0});
          polled.push_back(client.get());
        }
      }
      if (::poll(fds.data(), fds.size(), static_cast<int>(kPollPeriod.count())) < 0) continue;
      if (fds[2].revents & POLLIN) {
        uint64_t count = 0;
        [[maybe_unused]] auto read = ::read(wake_fd, &count, sizeof count);
      }
      std::lock_guard lock(mutex);
      if (fds[0].revents & POLLIN) accept_clients();
      if (fds[1].revents & POLLIN) connect_back(buffer, sizeof buffer);
      for (size_t i = 0; i < polled.size(); ++i) {
        serve(*polled[i], fds[3 + i].revents, buffer, sizeof buffer);
      }
      // Reports queued since the poll began go out now, not a poll period later.
      for (auto& client : clients) {
        if (client->state != Client::State::Connecting) write_out(*client);
      }
      std::erase_if(clients, [](const std::unique_ptr<Client>& client) {
        if (!client->closing) return false;
        ::close(client->fd);
        return true;
      });
    }
  }

  bool room_for_one_more() {
    if (clients.size() < options.max_clients) return true;
    ++stats.clients_refused;
    return false;
  }

  void add_client(int fd, Client::State state) {
    set_non_blocking(fd);
    const int on = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof on);
    auto client = std::make_unique<Client>();
    client->fd = fd;
    client->state = state;
    if (state == Client::State::AwaitingCookie) client->out = cookie();
    clients.push_back(std::move(client));
  }

  void accept_clients() {
    for (int fd; (fd = ::accept4(tcp_fd, nullptr, nullptr, SOCK_CLOEXEC)) >= 0;) {
      if (!room_for_one_more()) {
        ::close(fd);
        continue;
      }
      add_client(fd, Client::State::AwaitingCookie);
    }
  }

  // A UDP request names an address and a port; the connection goes to that port on the address
  // the datagram came from, whatever it names, so that nobody can make this server open
  // connections to a third host. A datagram's source can be forged, so each source gets at most
  // one connection under way and kMaxConnectBacksPerSource within kConnectBackWindow (VRPN's
  // client asks again every 2 s until it is connected).
  void connect_back(char* buffer, size_t size) {
    for (;;) {
      sockaddr_in source{};
      socklen_t length = sizeof source;
      const ssize_t n =
          ::recvfrom(udp_fd, buffer, size, 0, reinterpret_cast<sockaddr*>(&source), &length);
      if (n < 0) return;
      auto request = parse_request(std::string_view(buffer, static_cast<size_t>(n)));
      if (!request || source.sin_family != AF_INET) {
        ++stats.bad_requests;
        continue;
      }
      ++stats.connection_requests;
      if (request->sin_addr.s_addr != source.sin_addr.s_addr) ++stats.requests_naming_another_host;
      if (!may_connect_back_to(source.sin_addr.s_addr) || !room_for_one_more()) continue;
      sockaddr_in address = source;
      address.sin_port = request->sin_port;
      const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
      if (::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0 &&
          errno != EINPROGRESS) {
        ::close(fd);
        continue;
      }
      add_client(fd, Client::State::Connecting);
      clients.back()->connected_back_to = source.sin_addr.s_addr;
      connect_backs[source.sin_addr.s_addr].push_back(std::chrono::steady_clock::now());
    }
  }

  bool may_connect_back_to(in_addr_t source) {
    const auto now = std::chrono::steady_clock::now();
    for (auto entry = connect_backs.begin(); entry != connect_backs.end();) {
      auto& times = entry->second;
      while (!times.empty() && now - times.front() >= kConnectBackWindow) times.pop_front();
      entry = times.empty() ? connect_backs.erase(entry) : std::next(entry);
    }
    const bool under_way = std::any_of(clients.begin(), clients.end(), [&](const auto& client) {
      return client->connected_back_to == source && client->state != Client::State::Connected &&
             !client->closing;
    });
    auto made = connect_backs.find(source);
    if (under_way ||
        (made != connect_backs.end() && made->second.size() >= kMaxConnectBacksPerSource)) {
      ++stats.connect_backs_limited;
      return false;
    }
    return true;
  }

  void serve(Client& client, short revents, char* buffer, size_t size) {
    if (client.closing) return;
    if (client.state == Client::State::Connecting) {
      if (!(revents & (POLLOUT | POLLERR | POLLHUP))) return;
      int error = 0;
      socklen_t length = sizeof error;
      getsockopt(client.fd, SOL_SOCKET, SO_ERROR, &error, &length);
      if (error != 0) {
        client.closing = true;
        return;
      }
      client.state = Client::State::AwaitingCookie;
      client.out = cookie();
      return;
    }
    if (revents & (POLLIN | POLLHUP | POLLERR)) {
      const ssize_t n = ::recv(client.fd, buffer, size, 0);
      if (n > 0) {
        received(client, std::string_view(buffer, static_cast<size_t>(n)));
      } else if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK)) {
        client.closing = true;
        if (client.state == Client::State::Connected) ++stats.clients_closed;
      }
    }
  }

  void write_out(Client& client) {
    while (!client.closing && client.queued() > 0) {
      const ssize_t n =
          ::send(client.fd, client.out.data() + client.sent, client.queued(), MSG_NOSIGNAL);
      if (n < 0) {
        if (errno == EAGAIN || errno == EWOULDBLOCK) break;
        client.closing = true;
        if (client.state == Client::State::Connected) ++stats.clients_closed;
        return;
      }
      client.sent += static_cast<size_t>(n);
    }
    if (client.sent == client.out.size()) {
      client.out.clear();
      client.sent = 0;
    } else if (client.sent > (1 << 16)) {
      client.out.erase(0, client.sent);
      client.sent = 0;
    }
  }
};

std::optional<std::string> TrackerServerOptions::problem() const {
  in_addr parsed{};
  if (inet_pton(AF_INET, address.c_str(), &parsed) != 1) {
    return fmt::format("address: '{}' is not an IPv4 address", address);
  }
  if (max_queued_bytes == 0) return "max_queued_bytes: 0 leaves no room for a report";
  if (max_clients == 0) return "max_clients: 0; every client would be refused";
  return std::nullopt;
}

TrackerServer::TrackerServer(TrackerServerOptions options) {
  if (auto problem = options.problem()) {
    throw std::invalid_argument("TrackerServerOptions::" + *problem);
  }
  impl_ = std::make_unique<Impl>();
  impl_->options = options;
  impl_->listen(options);
  impl_->thread = std::thread([impl = impl_.get()] { impl->run(); });
}

TrackerServer::~TrackerServer() {
  impl_->stopping = true;
  impl_->wake();
  impl_->thread.join();
}

uint16_t TrackerServer::port() const { return impl_->port; }

bool TrackerServer::loopback_only() const { return impl_->loopback; }

void TrackerServer::report(const std::string& name, const TrackerReport& report) {
  Impl& s = *impl_;
  {
    std::lock_guard lock(s.mutex);
    ++s.stats.reports;
    auto [found, added] =
        s.tracker_ids.try_emplace(name, static_cast<int32_t>(s.tracker_names.size()));
    const int32_t id = found->second;
    if (added) {
      s.tracker_names.push_back(name);
      const std::string described =
          s.next_encoded(stamped(description(kSenderDescription, id, name), now_ns()));
      for (auto& client : s.clients) {
        if (client->state == Client::State::Connected) s.queue(*client, described);
      }
    }
    Message pose;
    pose.sender = id;
    pose.type = kPosQuat;
    pose.payload = pos_quat_payload(0, report.position, report.orientation.normalized());
    Message velocity;
    velocity.sender = id;
    velocity.type = kVelocity;
    const double angle = report.angular_velocity.norm() * kVelocityDt;
    const Eigen::Quaterniond turn =
        angle > 0
            ? Eigen::Quaterniond(Eigen::AngleAxisd(angle, report.angular_velocity.normalized()))
            : Eigen::Quaterniond::Identity();
    velocity.payload = velocity_payload(0, report.linear_velocity, turn, kVelocityDt);
    std::string bytes = s.next_encoded(stamped(pose, report.stamp_ns)) +
                        s.next_encoded(stamped(velocity, report.stamp_ns));
    for (auto& client : s.clients) {
      if (client->state == Client::State::Connected) s.queue(*client, bytes);
    }
    s.latest_report[id] = std::move(bytes);
  }
  s.wake();
}

size_t TrackerServer::clients() const {
  std::lock_guard lock(impl_->mutex);
  size_t connected = 0;
  for (const auto& client : impl_->clients) {
    if (client->state == Client::State::Connected && !client->closing) ++connected;
  }
  return connected;
}

TrackerServerStats TrackerServer::stats() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->stats;
}

}  // namespace mocap::vrpn
