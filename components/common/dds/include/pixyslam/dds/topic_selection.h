#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace pixyslam::dds {

// Shell-style match of a whole topic name: `*` any run of characters ('/'
// included), `?` one character; everything else literal.
bool glob_match(std::string_view pattern, std::string_view text);

// The result of select_topics(): the selected topics in the order of `known`,
// or the index of the first bad pattern and why.
struct TopicSelection {
  std::vector<std::string> topics;
  std::size_t bad_pattern = 0;  // index into the patterns when !error.empty()
  std::string error;            // "" when the selection is valid
};

// Selects topics of `known` with a list of patterns (config `logger.topics`):
// "pixyslam/odometry" (a name), "pixyslam/*" (a glob), "!pixyslam/ground_truth"
// (an exclusion, name or glob). A topic is selected when it matches at least
// one inclusion (every topic when the list has exclusions only) and no
// exclusion. Errors: a name that is not known, a glob that matches no known
// topic, a pattern given twice, an empty list, nothing selected. Pure.
TopicSelection select_topics(const std::vector<std::string>& patterns, const std::vector<std::string>& known);

}  // namespace pixyslam::dds
