// A VRPN tracker server: one tracker (sensor 0) per name, on VRPN's TCP port and its UDP
// connection requests, on a thread of its own.
//
// A VRPN client reaches it either way VRPN's own client library does: "Tracker0@host" lobs a
// UDP datagram "ADDRESS PORT" to the server's port and waits for the server to connect back to
// that TCP port; "Tracker0@tcp://host" connects to the server's TCP port directly. The server
// connects back to the port on the datagram's source address, never to another host the
// datagram names (VRPN's client names the address it sends from), at most 4 times in 10 s per
// source. Both ends
// then send their cookie; once the client's has come, the server describes its types and
// trackers, sends each tracker's latest report, and from then on every report. Everything goes
// over TCP (the server announces no UDP port, as a VRPN server behind a firewall does).
//
// Reports never wait for a client: each client has an output queue; one that holds more than
// max_queued_bytes (a client that reads too slowly or not at all) is dropped, as is one whose
// connection breaks or that sends what is not VRPN.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "outputs/vrpn_server/vrpn_protocol.hpp"

namespace mocap::vrpn {

struct TrackerServerOptions {
  std::string address = "127.0.0.1";  // IPv4 address to listen on; 0.0.0.0: every interface
  uint16_t port = kDefaultPort;       // TCP and UDP; 0: any free port (port() tells which)
  size_t max_queued_bytes = 1 << 20;  // per client
  size_t max_clients = 64;

  // Why these options cannot be used, naming the field ("address: 'localhost' is not an IPv4
  // address"); nullopt when they can. TrackerServer's constructor throws std::invalid_argument
  // with it.
  std::optional<std::string> problem() const;
};

struct TrackerServerStats {
  uint64_t clients_connected = 0;    // handshakes completed
  uint64_t clients_closed = 0;       // by the client, or broken
  uint64_t clients_too_slow = 0;     // dropped with a full queue
  uint64_t clients_refused = 0;      // not VRPN, or over max_clients
  uint64_t connection_requests = 0;  // UDP requests to connect back
  uint64_t bad_requests = 0;         // UDP datagrams that were no such request
  // Requests naming another address than their datagram's source (the connection still goes
  // to the source), and requests not followed: a connection to that source under way already,
  // or its limit reached.
  uint64_t requests_naming_another_host = 0;
  uint64_t connect_backs_limited = 0;
  uint64_t reports = 0;  // report() calls
  uint64_t pongs = 0;
};

// One tracker's state at one instant. Velocities are those of its origin and axes, in the frame
// of its position.
struct TrackerReport {
  int64_t stamp_ns = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
};

class TrackerServer {
 public:
  // Listens and starts the thread. Throws std::invalid_argument for options that cannot be used
  // (an address that is not an IPv4 address), std::runtime_error naming address:port when the
  // address is not this machine's or the port is taken.
  explicit TrackerServer(TrackerServerOptions options);
  // Closes every connection and joins the thread.
  ~TrackerServer();
  TrackerServer(const TrackerServer&) = delete;
  TrackerServer& operator=(const TrackerServer&) = delete;

  uint16_t port() const;
  bool loopback_only() const;

  // Thread-safe, never blocks on a client: queues the Pos_Quat and Velocity reports of tracker
  // `name` for every client (a new name is described to them first).
  void report(const std::string& name, const TrackerReport& report);

  size_t clients() const;
  TrackerServerStats stats() const;

  // The rotation sent in a Velocity report is the one over this many seconds.
  static constexpr double kVelocityDt = 0.01;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mocap::vrpn
