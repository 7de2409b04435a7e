// Help when a name is misspelled: for launch files, and for components' own files.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace mocap {

// " (did you mean 'rate_hz'?)" when a candidate is close to `word` (a typo, or a word cut
// short), otherwise the list of candidates: " (parameters: a, b)", or " (there are no
// parameters)" when there are none.
std::string did_you_mean(std::string_view word, const std::vector<std::string>& candidates,
                         std::string_view what);

}  // namespace mocap
