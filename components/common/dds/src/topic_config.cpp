#include "pixyslam/dds/topic_config.h"

#include "pixyslam/dds/cdr_payload.h"
#include "pixyslam/dds/topic_selection.h"

namespace pixyslam::dds {

std::vector<std::string> read_topic_patterns(config::YamlReader& section) {
  const std::vector<std::string>& all = known_topic_names();
  if (!section.has("topics")) return all;
  const std::vector<std::string> patterns = section.text_list("topics");
  if (patterns.empty()) section.fail("topics", "empty list (leave the key out for every topic)");
  const TopicSelection selection = select_topics(patterns, all);
  if (!selection.error.empty()) section.fail("topics[" + std::to_string(selection.bad_pattern) + "]", selection.error);
  return selection.topics;
}

}  // namespace pixyslam::dds
