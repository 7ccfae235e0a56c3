#include "pixyslam/log_tool/log_commands.h"

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <iomanip>
#include <map>
#include <string>
#include <limits>
#include <set>
#include <sstream>
#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/dds/topic_selection.h"
#include "pixyslam/dds/topics.h"
#include "pixyslam/log_tool/message_format.h"
#include "pixyslam/log_tool/sequence_check.h"
#include "pixyslam/mcap/mcap_reader.h"
#include "pixyslam/dds/cdr_payload.h"

namespace pixyslam::log_tool {

namespace {

// "2026-11-25 14:03:07.123 UTC" for nanoseconds since the epoch.
std::string utc_time(std::uint64_t ns) {
  const std::time_t t = static_cast<std::time_t>(ns / 1000000000ull);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char text[40];
  std::strftime(text, sizeof(text), "%Y-%m-%d %H:%M:%S", &tm);
  char out[48];
  std::snprintf(out, sizeof(out), "%s.%03u UTC", text, static_cast<unsigned>((ns / 1000000ull) % 1000ull));
  return out;
}

const char* yes_no(bool b) { return b ? "yes" : "no"; }

std::string compression_name(const std::string& c) { return c.empty() ? "none" : c; }

// "12.345 s" from nanoseconds.
std::string seconds(std::uint64_t ns) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(3) << static_cast<double>(ns) * 1e-9 << " s";
  return os.str();
}

std::string plural(std::uint64_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

// Where a damaged file is damaged, in one line.
std::string damage_summary(const mcap::McapReader& reader) {
  const mcap::McapDamage& d = reader.damage();
  std::string s = "first damage at offset " + std::to_string(d.intact_until) + "; " +
                  plural(d.records.size(), "damaged record", "damaged records") + ", " +
                  plural(d.bytes_skipped, "byte", "bytes") + " skipped, " +
                  plural(reader.diagnostics().size(), "diagnostic", "diagnostics") + "; ";
  s += d.footer_found ? "footer found" : "no footer";
  if (d.footer_found) s += d.chunk_index_used ? ", chunks located by the chunk index" : ", chunk index not used";
  return s;
}

std::string status_text(const mcap::McapReader& reader) {
  const mcap::McapRecovery& r = reader.recovery();
  const mcap::McapDamage& d = reader.damage();
  switch (reader.state()) {
    case mcap::McapFileState::kComplete:
      return std::string("complete (footer") + (r.summary_present ? " and summary" : "") + " present" +
             (r.summary_present ? "" : ", no summary section") + ", no problems)";
    case mcap::McapFileState::kNotClosed:
      return "RECOVERED, not closed (no footer; records intact up to offset " + std::to_string(d.intact_until) +
             ", " + std::to_string(r.bytes_ignored_at_end) + " bytes after it ignored)";
    case mcap::McapFileState::kDamaged: break;
  }
  return "DAMAGED (" + damage_summary(reader) + ")";
}

// The summary line of `info`: the same facts as the status, never contradicting it.
std::string summary_text(const mcap::McapReader& reader) {
  const mcap::McapRecovery& r = reader.recovery();
  const mcap::McapDamage& d = reader.damage();
  if (d.summary_found) return d.chunk_index_used ? "yes (chunk index used)" : "yes";
  if (r.summary_present) return "present but damaged (not used to find chunks)";
  return (d.footer_found || r.footer_present) ? "none (the footer points at no summary)" : "no";
}

// On `err`, for a damaged file: one line saying so, then every diagnostic
// with its offset (at most `max_lines`, 0 = all).
void report_damage(const mcap::McapReader& reader, std::ostream& err, std::size_t max_lines) {
  const std::string& path = reader.path();
  if (reader.state() == mcap::McapFileState::kNotClosed) {
    const mcap::McapRecovery& r = reader.recovery();
    err << path << ": not closed (no footer; records intact up to offset " << reader.damage().intact_until << ", "
        << r.bytes_ignored_at_end << " bytes after it ignored)\n";
    return;
  }
  if (reader.state() != mcap::McapFileState::kDamaged) return;
  err << path << ": damaged: " << damage_summary(reader) << "\n";
  std::size_t lines = 0;
  for (const mcap::McapDiagnostic& d : reader.diagnostics()) {
    if (max_lines > 0 && lines == max_lines) {
      err << path << ": " << reader.diagnostics().size() - lines
          << " more diagnostics (pixyslam_log info lists them all)\n";
      break;
    }
    err << path << ": offset " << d.offset << ": " << d.message << "\n";
    ++lines;
  }
}

}  // namespace

namespace {

const char* state_name(mcap::McapFileState state) {
  switch (state) {
    case mcap::McapFileState::kComplete: return "complete";
    case mcap::McapFileState::kNotClosed: return "not_closed";
    case mcap::McapFileState::kDamaged: break;
  }
  return "damaged";
}

// `info --json`: the file's facts as one JSON object.
Value info_value(const mcap::McapReader& reader, const std::string& path) {
  const mcap::McapRecovery& rec = reader.recovery();
  std::map<std::uint16_t, std::uint64_t> count;
  std::map<std::uint16_t, std::pair<std::uint64_t, std::uint64_t>> span;  // first, last log time
  for (const mcap::McapMessage& m : reader.messages()) {
    ++count[m.channel_id];
    auto [it, inserted] = span.try_emplace(m.channel_id, m.log_time_ns, m.log_time_ns);
    it->second.first = std::min(it->second.first, m.log_time_ns);
    it->second.second = std::max(it->second.second, m.log_time_ns);
  }
  std::uint64_t first = std::numeric_limits<std::uint64_t>::max(), last = 0;
  for (const auto& [id, times] : span) {
    first = std::min(first, times.first);
    last = std::max(last, times.second);
  }
  Value topics = Value::list();
  for (const mcap::McapChannel& c : reader.channels()) {
    const mcap::McapSchema* schema = reader.find_schema(c.schema_id);
    Value topic = Value::structure()
                      .add("topic", Value::string(c.topic))
                      .add("messages", Value::unsigned_integer(count[c.id]))
                      .add("schema", Value::string(schema ? schema->name : ""))
                      .add("message_encoding", Value::string(c.message_encoding));
    const auto s = span.find(c.id);
    if (s != span.end() && s->second.second > s->second.first) {
      topic.add("rate_hz", Value::number(static_cast<double>(count[c.id] - 1) /
                                         (static_cast<double>(s->second.second - s->second.first) * 1e-9)));
    }
    topics.push(std::move(topic));
  }
  std::uint64_t compressed = 0, uncompressed = 0;
  for (const mcap::McapChunkInfo& c : reader.chunks()) {
    compressed += c.compressed_size;
    uncompressed += c.uncompressed_size;
  }
  Value info = Value::structure()
                   .add("file", Value::string(path))
                   .add("size_bytes", Value::unsigned_integer(rec.file_size))
                   .add("state", Value::string(state_name(reader.state())))
                   .add("status", Value::string(status_text(reader)))
                   .add("messages", Value::unsigned_integer(reader.messages().size()));
  if (!reader.messages().empty()) {
    info.add("first_log_time_ns", Value::unsigned_integer(first))
        .add("last_log_time_ns", Value::unsigned_integer(last))
        .add("first_utc", Value::string(utc_time(first)))
        .add("last_utc", Value::string(utc_time(last)));
  }
  info.add("chunks", Value::unsigned_integer(reader.chunks().size()))
      .add("bytes_stored", Value::unsigned_integer(compressed))
      .add("bytes_uncompressed", Value::unsigned_integer(uncompressed))
      .add("topics", std::move(topics));
  if (!reader.clean()) {
    info.add("valid_bytes", Value::unsigned_integer(rec.valid_bytes))
        .add("bytes_ignored_at_end", Value::unsigned_integer(rec.bytes_ignored_at_end))
        .add("diagnostics", Value::unsigned_integer(reader.diagnostics().size()));
  }
  return info;
}

}  // namespace

int run_info(const std::string& path, bool json, std::ostream& out, std::ostream& err) {
  const mcap::McapReader reader(path);
  if (json) {
    out << to_json_line(info_value(reader, path)) << "\n";
    if (reader.state() != mcap::McapFileState::kDamaged) return 0;
    report_damage(reader, err, 0);
    return 1;
  }
  const mcap::McapRecovery& rec = reader.recovery();
  const auto& messages = reader.messages();

  out << "file:        " << path << "\n";
  out << "size:        " << rec.file_size << " bytes\n";
  out << "status:      " << status_text(reader) << "\n";
  out << "summary:     " << summary_text(reader) << ", footer: " << yes_no(rec.footer_present) << "\n";
  out << "header:      profile '" << reader.profile() << "', library '" << reader.library() << "'\n";

  std::uint64_t first = std::numeric_limits<std::uint64_t>::max();
  std::uint64_t last = 0;
  std::map<std::uint16_t, std::uint64_t> per_channel;
  std::map<std::uint16_t, std::pair<std::uint64_t, std::uint64_t>> channel_span;  // first, last log time
  for (const mcap::McapMessage& m : messages) {
    first = std::min(first, m.log_time_ns);
    last = std::max(last, m.log_time_ns);
    ++per_channel[m.channel_id];
    auto [it, inserted] = channel_span.try_emplace(m.channel_id, m.log_time_ns, m.log_time_ns);
    if (!inserted) {
      it->second.first = std::min(it->second.first, m.log_time_ns);
      it->second.second = std::max(it->second.second, m.log_time_ns);
    }
  }
  out << "messages:    " << messages.size();
  if (!messages.empty()) {
    out << " over " << seconds(last - first) << ", " << utc_time(first) << " .. " << utc_time(last) << " (log time "
        << first << " .. " << last << " ns)";
  }
  out << "\n";

  std::map<std::string, std::uint64_t> by_compression;
  std::uint64_t compressed = 0;
  std::uint64_t uncompressed = 0;
  for (const mcap::McapChunkInfo& c : reader.chunks()) {
    ++by_compression[compression_name(c.compression)];
    compressed += c.compressed_size;
    uncompressed += c.uncompressed_size;
  }
  out << "chunks:      " << reader.chunks().size();
  if (!reader.chunks().empty()) {
    out << " (";
    bool first_entry = true;
    for (const auto& [name, count] : by_compression) {
      out << (first_entry ? "" : ", ") << name << ": " << count;
      first_entry = false;
    }
    out << "), " << compressed << " bytes stored for " << uncompressed << " uncompressed";
  }
  out << "\n";

  out << "schemas:     " << reader.schemas().size() << "\n";
  for (const mcap::McapSchema& s : reader.schemas()) {
    out << "  " << s.id << "  " << s.name << "  (" << s.encoding << ", " << s.data.size() << " bytes)\n";
  }
  out << "topics:      " << reader.channels().size() << "\n";
  for (const mcap::McapChannel& c : reader.channels()) {
    const mcap::McapSchema* schema = reader.find_schema(c.schema_id);
    // The topic's rate between its own first and last message.
    char rate[32] = "";
    const auto span = channel_span.find(c.id);
    if (span != channel_span.end() && span->second.second > span->second.first) {
      std::snprintf(rate, sizeof(rate), "%9.2f Hz", static_cast<double>(per_channel[c.id] - 1) /
                                                        (static_cast<double>(span->second.second - span->second.first) * 1e-9));
    }
    out << "  " << std::left << std::setw(32) << c.topic << std::right << std::setw(8) << per_channel[c.id]
        << " messages" << rate << "  " << (schema ? schema->name : std::string("(no schema)")) << "  "
        << c.message_encoding;
    for (const auto& [key, value] : c.metadata) out << "  " << key << "=" << value;
    out << "\n";
  }

  if (!reader.clean()) {
    out << "recovery:\n"
        << "  header present " << yes_no(rec.header_present) << ", data end " << yes_no(rec.data_end_present)
        << ", summary " << yes_no(rec.summary_present) << ", footer " << yes_no(rec.footer_present) << "\n"
        << "  chunks complete " << rec.complete_chunks << ", rejected " << rec.rejected_chunks
        << "; messages recovered " << rec.messages_recovered << "\n"
        << "  valid bytes " << rec.valid_bytes << " of " << rec.file_size << ", ignored at end "
        << rec.bytes_ignored_at_end << "\n";
  }
  if (reader.state() == mcap::McapFileState::kNotClosed) {
    out << "diagnostics: " << reader.diagnostics().size() << "\n";
    for (const mcap::McapDiagnostic& d : reader.diagnostics()) {
      out << "  offset " << d.offset << ": " << d.message << "\n";
    }
  }
  if (reader.state() == mcap::McapFileState::kDamaged) {
    const mcap::McapDamage& damage = reader.damage();
    out << "damage:      " << plural(damage.records.size(), "damaged record", "damaged records") << ", "
        << plural(damage.bytes_skipped, "byte", "bytes") << " skipped in "
        << plural(damage.skipped.size(), "range", "ranges") << " (diagnostics on stderr)\n";
    for (const mcap::McapDamagedRecord& d : damage.records) {
      out << "  offset " << d.offset << " .. " << d.end << ": " << d.what << "\n";
    }
    report_damage(reader, err, 0);
    return 1;
  }
  return 0;
}

namespace {

// What one topic (channel) of a file holds.
struct TopicCheck {
  const mcap::McapChannel* channel = nullptr;
  std::string type_name;
  std::uint64_t messages = 0;
  std::uint64_t undecodable = 0;
  std::string first_error;
  std::uint64_t sequence_mismatches = 0;      // MCAP sequence != header seq (low 32 bits)
  std::uint64_t publish_time_mismatches = 0;  // MCAP publish_time != header stamp_ns
  std::map<std::string, std::vector<std::uint64_t>> seqs_by_writer;
};

}  // namespace

int run_check(const CheckRequest& request, std::ostream& out, std::ostream& err) {
  const mcap::McapReader reader(request.path);
  bool ok = true;

  if (reader.clean()) {
    out << "OK   file: complete, " << reader.messages().size() << " messages\n";
  } else {
    const bool pass = request.allow_recovered;
    ok = ok && pass;
    out << (pass ? "OK   " : "FAIL ") << "file: " << status_text(reader) << ", " << reader.diagnostics().size()
        << " diagnostics, " << reader.recovery().bytes_ignored_at_end << " bytes ignored at end"
        << (pass ? " (allowed)" : " (--allow-recovered to check it anyway)") << "\n";
    if (reader.state() == mcap::McapFileState::kDamaged) report_damage(reader, err, 20);
  }

  std::map<std::uint16_t, TopicCheck> topics;
  for (const mcap::McapChannel& c : reader.channels()) {
    TopicCheck& t = topics[c.id];
    t.channel = &c;
    const mcap::McapSchema* schema = reader.find_schema(c.schema_id);
    t.type_name = schema ? schema->name : "";
  }
  for (const mcap::McapMessage& m : reader.messages()) {
    auto it = topics.find(m.channel_id);
    if (it == topics.end()) continue;  // the reader reports messages of unknown channels
    TopicCheck& t = it->second;
    ++t.messages;
    dds::SampleHeader header;
    std::string error;
    if (t.channel->message_encoding != "cdr") {
      error = "message encoding '" + t.channel->message_encoding + "' is not cdr";
    } else if (dds::decode_header(t.type_name, m.data.data(), m.data.size(), header, error)) {
      // One sequence per writer: per robot, and per process on the diagnostics
      // topic, which every process writes (frame_id = the process).
      std::string writer = header.robot_id;
      if (t.channel->topic == dds::kDiagnosticsTopic) writer += " " + header.frame_id;
      t.seqs_by_writer[writer].push_back(header.seq);
      if (m.sequence != static_cast<std::uint32_t>(header.seq)) ++t.sequence_mismatches;
      if (m.publish_time_ns != header.stamp_ns) ++t.publish_time_mismatches;
      continue;
    }
    if (t.undecodable++ == 0) t.first_error = error;
  }

  std::set<std::string> seen_topics;
  for (const auto& [id, t] : topics) {
    const std::string& topic = t.channel->topic;
    seen_topics.insert(topic);
    // `pixyslam_log foxglove` adds channels drawn from the topics (Foxglove's own
    // schemas, no project header): listed, not checked.
    if (t.type_name.rfind("foxglove::", 0) == 0 && request.expected.count(topic) == 0) {
      out << "SKIP " << topic << ": " << t.messages << " messages of " << t.type_name
          << " (drawn from the recorded topics for Foxglove; no header to check)\n";
      continue;
    }
    std::vector<std::string> problems;
    if (t.undecodable > 0) {
      problems.push_back(std::to_string(t.undecodable) + " not decodable as '" + t.type_name +
                         "' (first: " + t.first_error + ")");
    }
    if (t.sequence_mismatches > 0) {
      problems.push_back(std::to_string(t.sequence_mismatches) + " with MCAP sequence != header.seq");
    }
    if (t.publish_time_mismatches > 0) {
      problems.push_back(std::to_string(t.publish_time_mismatches) + " with publish_time != header.stamp_ns");
    }
    const auto expected = request.expected.find(topic);
    if (expected != request.expected.end() && expected->second != t.messages) {
      problems.push_back("expected " + std::to_string(expected->second) + " messages");
    }
    std::vector<std::string> sequences;
    for (const auto& [robot, seqs] : t.seqs_by_writer) {
      const SequenceReport report = analyze_sequence(seqs);
      std::string line = describe(report);
      if (t.seqs_by_writer.size() > 1) line = robot + ": " + line;
      if (!report.complete()) problems.push_back("seq not exactly 1..N");
      sequences.push_back(line);
    }
    const bool topic_ok = problems.empty();
    ok = ok && topic_ok;
    out << (topic_ok ? "OK   " : "FAIL ") << topic << ": " << t.messages << " messages";
    for (const std::string& s : sequences) out << ", " << s;
    if (t.seqs_by_writer.size() == 1) out << " (" << (topic == dds::kDiagnosticsTopic ? "" : "robot ") << t.seqs_by_writer.begin()->first << ")";
    for (const std::string& p : problems) out << "; " << p;
    out << "\n";
  }
  for (const auto& [topic, count] : request.expected) {
    if (seen_topics.count(topic)) continue;
    ok = ok && count == 0;
    out << (count == 0 ? "OK   " : "FAIL ") << topic << ": no such topic in the file (expected " << count
        << " messages)\n";
  }
  out << (ok ? "check passed" : "check FAILED") << "\n";
  return ok ? 0 : 1;
}

namespace {

template <class Message>
bool decode_as(const std::vector<std::uint8_t>& bytes, Value& value, std::string& error) {
  Message message;
  if (!dds::from_cdr(bytes, message, error)) return false;
  value = to_value(message);
  return true;
}

// A recorded payload of `topic` as a field tree; false with `error` if undecodable.
bool decode_value(const std::string& topic, const std::vector<std::uint8_t>& bytes, Value& value, std::string& error) {
  bool decoded = false;
  if (dds::visit_topic_type(topic, [&](auto tag) {
        decoded = decode_as<typename decltype(tag)::type>(bytes, value, error);
      })) {
    return decoded;
  }
  error = "not a topic of this project";
  return false;
}

// Every message of `topic` in `path`, decoded, in file order. Throws naming
// the file and message index of an undecodable payload.
std::vector<Value> decoded_messages(const std::string& path, const std::string& topic) {
  const mcap::McapReader reader(path);
  const mcap::McapChannel* channel = reader.find_channel(topic);
  if (channel == nullptr) throw std::runtime_error(path + ": no channel '" + topic + "'");
  std::vector<Value> values;
  std::size_t index = 0;
  for (const mcap::McapMessage& m : reader.messages()) {
    if (m.channel_id != channel->id) continue;
    Value value = Value::structure();
    std::string error;
    if (!decode_value(topic, m.data, value, error)) {
      throw std::runtime_error(path + ": " + topic + " message " + std::to_string(index) + ": " + error);
    }
    values.push_back(std::move(value));
    ++index;
  }
  return values;
}

}  // namespace

int run_print(const PrintRequest& request, std::ostream& out, std::ostream& err) {
  const mcap::McapReader reader(request.path);
  std::set<std::string> printed;
  for (const mcap::McapChannel& channel : reader.channels()) printed.insert(channel.topic);
  if (!request.topics.empty()) {
    const dds::TopicSelection selection =
        dds::select_topics(request.topics, std::vector<std::string>(printed.begin(), printed.end()));
    if (!selection.error.empty()) {
      // Patterns no recording of this project could satisfy (an unknown name): a
      // command-line error (2), as echo, hz and record; a topic this file lacks: the input's (1).
      const dds::TopicSelection in_project = dds::select_topics(request.topics, dds::known_topic_names());
      const bool usage = !in_project.error.empty();
      const dds::TopicSelection& bad = usage ? in_project : selection;
      const std::string message =
          request.path + ": --topics '" + request.topics[bad.bad_pattern] + "': " + bad.error;
      if (usage) throw app::UsageError(message);
      throw std::runtime_error(message);
    }
    printed = std::set<std::string>(selection.topics.begin(), selection.topics.end());
  }
  int status = 0;
  for (const mcap::McapMessage& m : reader.messages()) {
    const mcap::McapChannel* channel = reader.find_channel(m.channel_id);
    if (channel == nullptr || printed.count(channel->topic) == 0) continue;
    Value value = Value::structure();
    std::string error;
    if (!decode_value(channel->topic, m.data, value, error)) {
      out << "# " << channel->topic << " log time " << m.log_time_ns << ": cannot decode: " << error << "\n";
      status = 1;
      continue;
    }
    Value record = Value::structure();
    record.add("topic", Value::string(channel->topic));
    record.add("log_time_ns", Value::unsigned_integer(m.log_time_ns));
    record.add("message", std::move(value));
    out << (request.json ? to_json_line(record) + "\n" : to_yaml_document(record));
  }
  // After the messages, so that it is the last thing a terminal shows.
  out.flush();
  report_damage(reader, err, 20);
  return reader.state() == mcap::McapFileState::kDamaged ? 1 : status;
}

int run_compare(const CompareRequest& request, std::ostream& out) {
  if (dds::find_topic(request.topic) == nullptr) {
    const std::string why = dds::select_topics({request.topic}, dds::known_topic_names()).error;
    throw app::UsageError("--topic: " + (why.empty() ? "'" + request.topic + "' is not one topic" : why));
  }
  const std::vector<Value> first = decoded_messages(request.first_path, request.topic);
  const std::vector<Value> second = decoded_messages(request.second_path, request.topic);
  // A misspelt field would silently compare everything, or pair by position.
  const Value* sample = !first.empty() ? &first.front() : !second.empty() ? &second.front() : nullptr;
  for (const auto* fields : {&request.ignored, &request.match}) {
    for (const std::string& f : *fields) {
      if (sample != nullptr && !field_path_exists(*sample, f)) {
        throw app::UsageError(std::string(fields == &request.ignored ? "--ignore" : "--match") + ": '" + f +
                              "' is not a field of " + request.topic + "'s messages");
      }
    }
  }
  out << request.topic << ": " << first.size() << " messages in " << request.first_path << ", " << second.size()
      << " in " << request.second_path << "\n";
  const MessagePairs paired = pair_messages(first, second, request.match);
  const std::size_t n = paired.pairs.size();
  bool same = paired.only_first.size() <= request.max_unmatched && paired.only_second.size() <= request.max_unmatched;

  std::int64_t min_offset = std::numeric_limits<std::int64_t>::max();
  std::int64_t max_offset = std::numeric_limits<std::int64_t>::min();
  std::size_t differing = 0, differing_after = 0;
  std::size_t lines = 0;
  const std::size_t before_unmatched = request.until_unmatched ? pairs_before_first_unmatched(paired) : n;
  for (std::size_t k = 0; k < n; ++k) {
    const auto [i, j] = paired.pairs[k];
    const Value* a = first[i].find("header.stamp_ns");
    const Value* b = second[j].find("header.stamp_ns");
    if (a != nullptr && b != nullptr) {
      const auto offset = static_cast<std::int64_t>(b->uint_value() - a->uint_value());
      min_offset = std::min(min_offset, offset);
      max_offset = std::max(max_offset, offset);
    }
    const std::vector<std::string> differences = compare_values(
        first[i], second[j], request.ignored, request.tolerance, std::max<std::size_t>(1, request.max_lines));
    if (differences.empty()) continue;
    if (k >= before_unmatched) {
      ++differing_after;
      continue;
    }
    ++differing;
    for (const std::string& d : differences) {
      if (lines >= request.max_lines) break;
      out << "  message " << i << (i == j ? "" : " (" + std::to_string(j) + " in the second)") << ": " << d << "\n";
      ++lines;
    }
  }
  if (n > 0 && min_offset <= max_offset) {
    out << "header stamps: second - first = ";
    if (min_offset == max_offset) {
      out << "constant " << min_offset << " ns\n";
    } else {
      out << "varies from " << min_offset << " to " << max_offset << " ns\n";
    }
  }
  std::string ignored;
  for (const std::string& f : request.ignored) ignored += (ignored.empty() ? "" : ", ") + f;
  if (differing == 0) {
    out << n - differing_after << " messages compared: identical in every field"
        << (ignored.empty() ? "" : " except the ignored " + ignored)
        << (request.tolerance > 0 ? " (relative tolerance " + format_double(request.tolerance) + ")" : "") << "\n";
  } else {
    out << differing << " of " << n << " messages differ\n";
    same = false;
  }
  if (request.until_unmatched) {
    out << before_unmatched << " of " << n << " pairs before the first message without a partner; "
        << differing_after << " after it differ (allowed: --until-unmatched)\n";
    if (!until_unmatched_passes(n, differing, differing_after)) {
      out << "too few identical pairs: " << n - differing - differing_after << " of " << n
          << " (at least half must be)\n";
      same = false;
    }
  }
  if (!request.match.empty()) {
    std::string fields;
    for (const std::string& f : request.match) fields += (fields.empty() ? "" : ",") + f;
    out << "paired by " << fields << ": " << paired.only_first.size() << " only in the first, "
        << paired.only_second.size() << " only in the second (at most " << request.max_unmatched << " each)\n";
  } else if (first.size() != second.size()) {
    out << "message counts differ\n";
  }
  out << (same ? "SAME" : "DIFFERENT") << "\n";
  return same ? 0 : 1;
}

}  // namespace pixyslam::log_tool
