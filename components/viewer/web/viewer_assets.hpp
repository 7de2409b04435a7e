// The built-in viewer's files (this folder), compiled in by embed_files.cmake.
#pragma once

#include <string_view>
#include <vector>

namespace mocap::foxglove {

struct ViewerAsset {
  std::string_view path;  // "/index.html"
  std::string_view content_type;
  std::string_view body;
};

const std::vector<ViewerAsset>& viewer_assets();

}  // namespace mocap::foxglove
