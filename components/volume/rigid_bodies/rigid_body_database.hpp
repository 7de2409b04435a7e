// Rigid bodies of any shape: each is three or more markers at fixed positions in its own frame,
// identified among a volume's triangulated markers by the distances between its markers (no
// cross-ratio, no plane). A YAML file lists them:
//
//   bodies:
//     - name: wand
//       markers: [[0, 0, 0], [0.10, 0, 0], [0.25, 0.03, 0]]   # metres, the body's frame
//     - name: drone
//       markers: [[0.1, 0, 0], [0, 0.12, 0], [-0.1, 0, 0.02], [0, -0.07, 0.04]]
//       streaming_id: 7     # optional: its id to NatNet clients (Motive's "Streaming ID")
//
// Two bodies that the distances cannot tell apart within the identification's tolerance (the
// same shape, or one the shape of part of the other) are an error when the file is read, with
// both names: in a volume they would be taken for each other.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace mocap::volume {

// Streaming ids (NatNet's rigid body ids) are 1 to this: a labeled marker's id holds its
// body's in 16 bits.
inline constexpr int32_t kMaxStreamingId = 32767;

struct RigidBody {
  std::string name;
  std::vector<Eigen::Vector3d> markers;                // metres, in the body's frame
  std::optional<int32_t> streaming_id = std::nullopt;  // none: by its place (natnet_server)
};

class RigidBodyError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct RigidBodyDatabase {
  std::vector<RigidBody> bodies;
};

// Markers closer than this within a body cannot be told apart once triangulated.
inline constexpr double kMinMarkerSeparation = 0.01;  // metres

// The bodies of `text` (`source` names it in messages: "bodies.yaml:7: ..."). Throws
// RigidBodyError for a malformed file, a streaming_id outside 1..kMaxStreamingId or given
// twice, a body of fewer than three markers or with markers
// closer than kMinMarkerSeparation, a name given twice, and two bodies that identification
// with `tolerance` (metres) and `min_markers` (rigid_body_identification.hpp) cannot tell
// apart: one whose markers, measured with errors up to the tolerance, could be taken for
// `min_markers` or more of the other's.
RigidBodyDatabase parse_rigid_bodies(const std::string& text, const std::string& source,
                                     double tolerance, int min_markers);
RigidBodyDatabase load_rigid_bodies(const std::string& path, double tolerance, int min_markers);

// A min_markers that looks for no confusion (more markers than any body has): for readers of a
// file whose bodies they only name, the fusion having checked it with its own tolerance.
inline constexpr int kNoConfusionCheck = 1 << 20;

// A way `count` markers of `seen` could be taken for `count` of `taken_for`'s: their distances
// differ by up to twice `tolerance` and a rotation maps one set onto the other (a mirror image
// does not confuse). With `same` (one body against itself), the markers taken for themselves
// do not count: a body that maps onto itself so is symmetric, its orientation ambiguous. The
// markers of each side, or nothing.
std::optional<std::pair<std::vector<int>, std::vector<int>>> marker_confusion(
    const RigidBody& seen, const RigidBody& taken_for, size_t count, double tolerance, bool same);

}  // namespace mocap::volume
