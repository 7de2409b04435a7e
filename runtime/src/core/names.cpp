#include "core/names.hpp"

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

namespace {

std::vector<std::string_view> segments(std::string_view topic) {
  std::vector<std::string_view> out;
  size_t start = 1;  // after the leading '/'
  while (start <= topic.size()) {
    size_t end = topic.find('/', start);
    if (end == std::string_view::npos) end = topic.size();
    out.push_back(topic.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

bool is_placeholder(std::string_view segment) {
  return segment.size() > 2 && segment.front() == '{' && segment.back() == '}';
}

}  // namespace

bool is_topic_family(std::string_view topic) { return topic.find('{') != std::string_view::npos; }

bool valid_topic_family(std::string_view family) {
  if (family.size() < 2 || family.front() != '/') return false;
  for (std::string_view segment : segments(family)) {
    if (segment.empty()) return false;
    std::string_view word =
        is_placeholder(segment) ? segment.substr(1, segment.size() - 2) : segment;
    bool plain = std::all_of(word.begin(), word.end(), [](char c) {
      return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
    });
    if (!plain) return false;
  }
  return true;
}

std::optional<std::vector<std::string>> match_topic_family(std::string_view family,
                                                           std::string_view topic) {
  if (!valid_topic_name(topic)) return std::nullopt;
  std::vector<std::string_view> pattern = segments(family), parts = segments(topic);
  if (pattern.size() != parts.size()) return std::nullopt;
  std::vector<std::string> values;
  for (size_t i = 0; i < pattern.size(); ++i) {
    if (is_placeholder(pattern[i])) {
      values.emplace_back(parts[i]);
    } else if (pattern[i] != parts[i]) {
      return std::nullopt;
    }
  }
  return values;
}

std::string instantiate_topic_family(std::string_view family,
                                     const std::vector<std::string>& values) {
  std::string topic;
  size_t next = 0;
  for (std::string_view segment : segments(family)) {
    topic += '/';
    topic += is_placeholder(segment) && next < values.size() ? std::string_view(values[next++])
                                                             : segment;
  }
  return topic;
}

bool topics_overlap(std::string_view a, std::string_view b) {
  if (a == b) return true;
  std::vector<std::string_view> x = segments(a), y = segments(b);
  if (x.size() != y.size()) return false;
  for (size_t i = 0; i < x.size(); ++i) {
    if (x[i] != y[i] && !is_placeholder(x[i]) && !is_placeholder(y[i])) return false;
  }
  return is_topic_family(a) || is_topic_family(b);
}

bool valid_component_name(std::string_view name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
  });
}

const std::string* nearest_spelling(std::string_view word,
                                    const std::vector<std::string>& candidates, size_t max_edits) {
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
  if (best != nullptr && best_distance <= std::max(max_edits, word.size() / 4)) return best;
  return nullptr;
}

std::string did_you_mean(std::string_view word, const std::vector<std::string>& candidates,
                         std::string_view what) {
  if (const std::string* best = nearest_spelling(word, candidates)) {
    return fmt::format(" (did you mean '{}'?)", *best);
  }
  if (candidates.empty()) return fmt::format(" (there are no {})", what);
  return fmt::format(" ({}: {})", what, fmt::join(candidates, ", "));
}

}  // namespace mocap
