// A NatNet server: what a Motive host offers its clients, on a thread of its own.
//
// The command port (1510) answers NAT_CONNECT with the server's description, NAT_REQUEST_MODELDEF
// with the bodies' descriptions, the requests below, keep-alives and echo requests; anything else
// NatNet-shaped gets NAT_UNRECOGNIZED_REQUEST. Frames leave from the data port (1511), as Motive
// sends them:
//   - unicast (the default): to the address and port each client's NAT_CONNECT came from (where
//     OptiTrack's PacketClient, Python client and NatNetLib read them), in the bitstream version
//     that client asked for in its connection options or by "Bitstream,M.m"; a client that sends
//     nothing for client_timeout_s (NatNet's clients send a keep-alive every second or two) is no
//     longer sent to;
//   - multicast: to group:data_port on one interface, TTL 1, in `version`.
//
// Requests understood: "Bitstream" (the client's version, "Bitstream,4.1"), "Bitstream,M.m" (0:
// done, 1: not a version this server writes, or multicast, where every client shares one),
// "FrameRate" (float, frames per second), "UnitsToMillimeters" (float 1000: positions are metres),
// "CurrentMode" (0: live).
//
// Nothing that arrives can make the server send to a third host or send much: it answers only the
// address a request came from, at most replies_per_s a second per source address (burst
// reply_burst) and 20 times that over all sources, and adds a unicast client only within that rate;
// it keeps a fixed record per client, at most max_clients of them, and forgets a client that sends
// what is not NatNet. Frames never wait for a client: a datagram the kernel cannot take at once is
// counted and dropped. What NatNet itself allows stays: a forged NAT_CONNECT (UDP's source can be
// forged, and NatNet has no handshake to prove it) draws up to client_timeout_s of frames to that
// source, unless it is forged again.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "outputs/natnet_server/natnet_protocol.hpp"

namespace mocap::natnet {

struct ServerOptions {
  std::string address = "127.0.0.1";  // IPv4 address to listen on; 0.0.0.0: every interface
  uint16_t command_port = kDefaultCommandPort;  // 0: any free port (command_port() tells which)
  // Frames leave from it (shared with multicast clients of this host), and multicast goes to it;
  // 0: any free port (the server info tells clients which).
  uint16_t data_port = kDefaultDataPort;
  bool multicast = false;
  std::string multicast_group = kDefaultMulticastGroup;
  // The interface multicast frames leave by, by name ("eth0"); empty: "lo" when `address` is a
  // loopback address, otherwise the interface of `address` (0.0.0.0: the kernel's choice).
  std::string multicast_interface = {};
  Version version = kDefaultVersion;  // frames to clients that ask for none, and multicast
  size_t max_clients = 16;
  double client_timeout_s = 5;
  double replies_per_s = 20;
  double reply_burst = 40;
  std::string application = "mocap-graph";

  // Why these options cannot be used, naming the field ("address: 'localhost' is not an IPv4
  // address"); nullopt when they can. Server's constructor throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

struct ServerStats {
  uint64_t clients_connected = 0;  // NAT_CONNECTs from new clients accepted
  uint64_t clients_refused = 0;    // over max_clients
  uint64_t clients_timed_out = 0;  // silent for client_timeout_s
  uint64_t clients_disconnected = 0;
  uint64_t clients_dropped_malformed = 0;  // a client that sent what is not NatNet
  uint64_t requests = 0;                   // well-formed requests read
  uint64_t malformed = 0;                  // datagrams that were not NatNet
  uint64_t unrecognized = 0;               // NatNet requests answered as unrecognized
  uint64_t replies_limited = 0;            // answers not sent: their source's rate spent
  uint64_t frames = 0;                     // send_frame() calls
  uint64_t frames_too_large = 0;           // frames cut to fit a datagram (markers left out)
  uint64_t datagrams_sent = 0;             // frames to clients or the group
  uint64_t datagrams_dropped = 0;          // the kernel could not take them at once
};

class Server {
 public:
  // Listens and starts the thread. Throws std::invalid_argument for options that cannot be used,
  // std::runtime_error naming address:port when the address is not this machine's or the port is
  // taken, or the multicast interface does not exist.
  explicit Server(ServerOptions options);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  uint16_t command_port() const;
  uint16_t data_port() const;
  bool loopback_only() const;

  // Thread-safe. The bodies (and marker sets) described to clients from now on; the next frame
  // says the tracked models changed.
  void set_descriptions(Descriptions descriptions);

  // Thread-safe, never blocks on a client: the frame, numbered by the server, to every unicast
  // client in its version (or to the group), with its transmit stamp set as it leaves. A frame
  // over a datagram's size leaves out labeled markers, then the legacy list, and is counted.
  void send_frame(FrameOfData frame);

  size_t clients() const;
  ServerStats stats() const;

  // The high-resolution clock of the stamps: the system clock in nanoseconds since the epoch.
  static uint64_t now_ticks();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mocap::natnet
