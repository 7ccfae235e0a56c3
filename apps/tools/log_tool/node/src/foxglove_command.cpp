#include <algorithm>
#include <map>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixyslam/dds/topics.h"
#include "pixyslam/foxglove/visualiser.h"
#include "pixyslam/log_tool/log_commands.h"
#include "pixyslam/mcap/mcap_reader.h"
#include "pixyslam/mcap/mcap_writer.h"

namespace pixyslam::log_tool {

namespace {

mcap::McapCompression compression_of(const std::string& name) {
  if (name == "none") return mcap::McapCompression::kNone;
  if (name == "lz4") return mcap::McapCompression::kLz4;
  if (name == "zstd") {
    return mcap::mcap_compression_available(mcap::McapCompression::kZstd) ? mcap::McapCompression::kZstd
                                                                           : mcap::McapCompression::kNone;
  }
  throw std::invalid_argument("--compression '" + name + "': none, zstd or lz4");
}

}  // namespace

int run_foxglove(const FoxgloveRequest& request, std::ostream& err) {
  const mcap::McapReader reader(request.input_path);
  mcap::McapWriterOptions options;
  options.profile = reader.profile();
  options.compression = compression_of(request.compression);
  mcap::McapWriter writer(request.output_path, options);

  // The input's schemas and channels, renumbered in the output.
  std::map<std::uint16_t, std::uint16_t> schema_ids, channel_ids;
  for (const mcap::McapSchema& s : reader.schemas()) schema_ids[s.id] = writer.add_schema(s.name, s.encoding, s.data);
  std::map<std::uint16_t, std::string> type_of;  // input channel -> schema name
  for (const mcap::McapChannel& c : reader.channels()) {
    const std::uint16_t schema = c.schema_id == 0 ? 0 : schema_ids.at(c.schema_id);
    channel_ids[c.id] = writer.add_channel(c.topic, c.message_encoding, schema, c.metadata);
    const mcap::McapSchema* s = reader.find_schema(c.schema_id);
    if (s != nullptr) type_of[c.id] = s->name;
  }
  // The visual channels, one schema per Foxglove type.
  const std::vector<foxglove::VisualChannelInfo>& visuals = foxglove::visual_channels();
  std::map<std::string, std::uint16_t> visual_schemas;
  std::vector<std::uint16_t> visual_channels;
  for (const foxglove::VisualChannelInfo& v : visuals) {
    auto [it, added] = visual_schemas.emplace(v.schema_name, 0);
    if (added) it->second = writer.add_schema(v.schema_name, "omgidl", msg::idl_text(v.idl_stem));
    visual_channels.push_back(writer.add_channel(v.topic, "cdr", it->second, {{"source", "pixyslam_log foxglove"}}));
  }

  // In log-time order, as a player would deliver them.
  std::vector<const mcap::McapMessage*> messages;
  for (const mcap::McapMessage& m : reader.messages()) messages.push_back(&m);
  std::stable_sort(messages.begin(), messages.end(),
                   [](const auto* a, const auto* b) { return a->log_time_ns < b->log_time_ns; });

  foxglove::Visualiser visualiser;
  std::vector<std::uint64_t> written(visuals.size(), 0);
  std::uint64_t malformed = 0;
  std::vector<foxglove::VisualMessage> out;
  for (const mcap::McapMessage* m : messages) {
    writer.write_message(channel_ids.at(m->channel_id), m->sequence, m->log_time_ns, m->publish_time_ns, m->data);
    const auto type = type_of.find(m->channel_id);
    if (type == type_of.end()) continue;
    std::string error;
    if (!visualiser.on_payload(type->second, m->data, out, error)) {
      if (malformed++ == 0) {
        err << "pixyslam_log foxglove: " << request.input_path << ": a " << type->second << " (log time "
            << m->log_time_ns << ") does not decode: " << error << "; skipped\n";
      }
      continue;
    }
    for (const foxglove::VisualMessage& v : out) {
      const std::size_t i = static_cast<std::size_t>(v.channel);
      ++written[i];
      writer.write_message(visual_channels[i], static_cast<std::uint32_t>(written[i]), m->log_time_ns, v.stamp_ns,
                           v.cdr);
    }
  }
  writer.close();

  err << "pixyslam_log foxglove: " << request.output_path << ": " << messages.size() << " messages copied\n";
  for (std::size_t i = 0; i < visuals.size(); ++i) {
    err << "  " << visuals[i].topic << " (" << visuals[i].schema_name << "): " << written[i] << " messages\n";
  }
  const bool damaged = reader.state() != mcap::McapFileState::kComplete;
  if (damaged) err << "pixyslam_log foxglove: " << request.input_path << " is damaged; converted what was readable\n";
  if (malformed > 0) err << "pixyslam_log foxglove: " << malformed << " messages did not decode (skipped)\n";
  return malformed > 0 || damaged ? 1 : 0;
}

}  // namespace pixyslam::log_tool
