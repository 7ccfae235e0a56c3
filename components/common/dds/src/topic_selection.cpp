#include "pixyslam/dds/topic_selection.h"

#include <algorithm>
#include <set>

namespace pixyslam::dds {

bool glob_match(std::string_view pattern, std::string_view text) {
  // Iterative match with backtracking to the last '*'.
  std::size_t p = 0;
  std::size_t t = 0;
  std::size_t star = std::string_view::npos;
  std::size_t star_text = 0;
  while (t < text.size()) {
    if (p < pattern.size() && (pattern[p] == '?' || pattern[p] == text[t])) {
      ++p;
      ++t;
    } else if (p < pattern.size() && pattern[p] == '*') {
      star = p++;
      star_text = t;
    } else if (star != std::string_view::npos) {
      p = star + 1;
      t = ++star_text;
    } else {
      return false;
    }
  }
  while (p < pattern.size() && pattern[p] == '*') ++p;
  return p == pattern.size();
}

namespace {

bool is_glob(std::string_view pattern) { return pattern.find_first_of("*?") != std::string_view::npos; }

}  // namespace

TopicSelection select_topics(const std::vector<std::string>& patterns, const std::vector<std::string>& known) {
  TopicSelection out;
  if (patterns.empty()) {
    out.error = "empty list (leave the key out to record every topic)";
    return out;
  }
  std::vector<std::string_view> include;
  std::vector<std::string_view> exclude;
  std::set<std::string> seen;
  for (std::size_t i = 0; i < patterns.size(); ++i) {
    const std::string& raw = patterns[i];
    const bool negative = !raw.empty() && raw[0] == '!';
    const std::string_view pattern = negative ? std::string_view(raw).substr(1) : std::string_view(raw);
    const auto fail = [&](const std::string& why) {
      out.bad_pattern = i;
      out.error = why;
      out.topics.clear();
      return out;
    };
    if (pattern.empty()) return fail("empty topic pattern");
    if (!seen.insert(raw).second) return fail("topic '" + raw + "' given twice");
    const bool matches_any = std::any_of(known.begin(), known.end(),
                                         [&](const std::string& topic) { return glob_match(pattern, topic); });
    if (!matches_any) {
      std::string list;
      for (const std::string& topic : known) list += (list.empty() ? "" : ", ") + topic;
      return fail(is_glob(pattern) ? "pattern '" + std::string(pattern) + "' matches no known topic (known: " + list + ")"
                                   : "unknown topic '" + std::string(pattern) + "' (known: " + list + ")");
    }
    (negative ? exclude : include).push_back(pattern);
  }
  for (const std::string& topic : known) {
    const auto matches = [&](std::string_view p) { return glob_match(p, topic); };
    const bool in = include.empty() || std::any_of(include.begin(), include.end(), matches);
    if (in && std::none_of(exclude.begin(), exclude.end(), matches)) out.topics.push_back(topic);
  }
  if (out.topics.empty()) {
    out.bad_pattern = patterns.size() - 1;
    out.error = "the patterns select no topic";
  }
  return out;
}

}  // namespace pixyslam::dds
