// Help when a name is misspelled: for launch files, and for components' own files.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace mocap {

// The candidate `word` most likely stands for: one within max(max_edits, size of word / 4)
// edits (a typo), or one that `word` begins, 3 letters at least (cut short); nullptr if none.
const std::string* nearest_spelling(std::string_view word,
                                    const std::vector<std::string>& candidates,
                                    size_t max_edits = 2);

// " (did you mean 'rate_hz'?)" when a candidate is close to `word` (nearest_spelling),
// otherwise the list of candidates: " (parameters: a, b)", or " (there are no parameters)"
// when there are none.
std::string did_you_mean(std::string_view word, const std::vector<std::string>& candidates,
                         std::string_view what);

}  // namespace mocap
