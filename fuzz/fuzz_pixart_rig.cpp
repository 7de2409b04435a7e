// PixArt rig files (pixart_rig.hpp, config/pixart/rig.yaml), as the localizer, the simulated
// box and mocap_calibrate --rig read them: parse_rig() returns a rig or throws RigError
// starting with the file's name, nothing else (a camera file's errors too). The text up to the
// first NUL is the rig; each further NUL-separated part is the next camera file it names
// ("camera_file"), the last part standing for the rest, all in the scratch folder the rig is
// read from. Rigs with '/' or '\' are skipped, so that no camera file lies outside that folder
// (scratch_files.hpp).
#include <cstdint>
#include <cstdlib>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz/rigid_transform.hpp"
#include "fuzz/scratch_files.hpp"
#include "pixart/pixart_rig/pixart_rig.hpp"

namespace {

using namespace mocap::pixart;

using fuzz::is_rigid;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::vector<std::string_view> parts =
      fuzz::split_at_nul({reinterpret_cast<const char*>(data), size});
  if (fuzz::could_name_a_path(parts[0])) return 0;
  const std::filesystem::path& folder = fuzz::fresh_scratch_folder("fuzz_pixart_rig");
  fuzz::write_files(folder, fuzz::values_after(parts[0], "camera_file"),
                    {parts.begin() + 1, parts.end()});
  Rig rig;
  try {
    rig = parse_rig(std::string(parts[0]), "rig.yaml", folder.string());
  } catch (const RigError& error) {
    if (!std::string_view(error.what()).starts_with("rig.yaml")) std::abort();
    return 0;
  }
  // The localizer looks cameras up by id and projects through every one.
  std::set<int> ids;
  for (const RigCamera& camera : rig.cameras) {
    if (!camera.model || !ids.insert(camera.camera_id).second ||
        !is_rigid(camera.world_from_camera)) {
      std::abort();
    }
  }
  if (rig.cameras.empty()) std::abort();
  return 0;
}
