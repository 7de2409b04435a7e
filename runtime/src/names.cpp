#include "names.hpp"

#include <algorithm>
#include <cctype>

#include <fmt/format.h>

namespace mocap {
namespace {

size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

}  // namespace

bool valid_topic_name(std::string_view topic) {
  if (topic.size() < 2 || topic.front() != '/' || topic.back() == '/') return false;
  if (topic.find("//") != std::string_view::npos) return false;
  return std::all_of(topic.begin(), topic.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '/';
  });
}

bool valid_component_name(std::string_view name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
  });
}

std::string did_you_mean(std::string_view word, const std::vector<std::string>& candidates,
                         std::string_view what) {
  const std::string* best = nullptr;
  size_t best_distance = 0;
  for (const std::string& candidate : candidates) {
    // A word cut short ("domain" for "domain_id") is as good as a typo.
    bool prefix = word.size() >= 3 && std::string_view(candidate).starts_with(word);
    size_t distance = prefix ? 1 : edit_distance(word, candidate);
    if (best == nullptr || distance < best_distance) {
      best = &candidate;
      best_distance = distance;
    }
  }
  if (best != nullptr && best_distance <= std::max<size_t>(2, word.size() / 4)) {
    return fmt::format(" (did you mean '{}'?)", *best);
  }
  if (candidates.empty()) return fmt::format(" (there are no {})", what);
  return fmt::format(" ({}: {})", what, fmt::join(candidates, ", "));
}

}  // namespace mocap
