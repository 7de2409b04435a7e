// Camera files (camera_file.hpp), as the pose estimator, the PixArt localizer and a rig's
// camera_file entries read them: parse_camera_file() returns a camera or throws
// CameraFileError starting with the file's name, nothing else. What parses must go through the
// writer and back: the same model and names, the pose within rounding (camera_file.hpp).
// The parser takes text (load_camera_file() only reads the file), so no file is involved.
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include <mocap/calibration/camera_factory.hpp>
#include <mocap/calibration/camera_file.hpp>

namespace {

using namespace mocap::calibration;

// Whether a name must read back as written. The parser keeps any bytes, but yaml-cpp's emitter
// writes U+FFFD for bytes that are not UTF-8 and for Unicode noncharacters, so only ASCII
// names are compared (the rest is a known difference, not what this harness looks for).
bool same_name(const std::string& written, const std::string& read) {
  const bool ascii = std::all_of(written.begin(), written.end(),
                                 [](char c) { return static_cast<unsigned char>(c) < 0x80; });
  return !ascii || written == read;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  CameraFile camera;
  try {
    camera = parse_camera_file(std::string(reinterpret_cast<const char*>(data), size), "cam.yaml");
  } catch (const CameraFileError& error) {
    if (!std::string_view(error.what()).starts_with("cam.yaml")) std::abort();
    return 0;
  }
  // The writer's own text must parse: an error here escapes as a crash.
  const CameraFile again = parse_camera_file(format_camera_file(camera), "written.yaml");
  const CameraModel& model = *camera.model;
  if (!same_name(camera.name, again.name) || !same_name(camera.frame_id, again.frame_id) ||
      again.model->type() != model.type() || again.model->width() != model.width() ||
      again.model->height() != model.height() ||
      camera_parameters(*again.model) != camera_parameters(model) ||
      again.world_from_camera.has_value() != camera.world_from_camera.has_value()) {
    std::abort();
  }
  if (camera.world_from_camera &&
      !again.world_from_camera->isApprox(*camera.world_from_camera, 1e-12)) {
    std::abort();
  }
  return 0;
}
