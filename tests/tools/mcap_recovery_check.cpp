// Reads an MCAP file the way it is left by a killed logger (McapReader
// recovery) and checks one topic's messages: seq exactly 1..K in file order
// (nothing missing inside what was recovered), no chunk rejected, every
// complete chunk's messages present.
//   mcap_recovery_check FILE --topic T [--sent S --max-loss L] [--expect-footer 0|1]
// With --sent: K must be at least S - L (S = messages published before the
// writer died; L = what the open chunk and the queue may hold).
// Prints the recovery report and "recovered T K"; exit 0 when every check
// passes, 1 otherwise, 2 on usage errors.
#include <cstdio>
#include <exception>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/log_tool/sequence_check.h"
#include "pixyslam/mcap/mcap_reader.h"

namespace pixyslam {
namespace {

int run(int argc, char** argv) {
  std::string path, topic, expect_footer;
  double sent = 0.0, max_loss = 0.0;
  app::Cli cli{"mcap_recovery_check", "Checks one topic of an MCAP file left by a killed logger: seq 1..K in order, "
                                      "no chunk rejected; exit 0 when every check passes, 1 otherwise."};
  cli.option("file", path, "the MCAP file").required().existing_file().type("FILE");
  cli.option("--topic", topic, "the topic to check").required().type("T");
  app::Cli::Option& sent_option =
      cli.option("--sent", sent, "messages published before the writer died").non_negative().type("S");
  app::Cli::Option& loss_option =
      cli.option("--max-loss", max_loss, "what the open chunk and the queue may hold").non_negative().type("L");
  sent_option.needs(loss_option);
  loss_option.needs(sent_option);
  cli.option("--expect-footer", expect_footer, "whether the file must end with a footer").choices({"0", "1"});
  if (const auto done = cli.parse(argc, argv)) return *done;
  const mcap::McapReader reader(path);
  const mcap::McapRecovery& r = reader.recovery();
  std::printf("file %s: %llu bytes, valid %llu, ignored at end %llu\n", path.c_str(),
              static_cast<unsigned long long>(r.file_size), static_cast<unsigned long long>(r.valid_bytes),
              static_cast<unsigned long long>(r.bytes_ignored_at_end));
  std::printf("header %d, data end %d, summary %d, footer %d; chunks complete %llu, rejected %llu; messages %llu\n",
              r.header_present, r.data_end_present, r.summary_present, r.footer_present,
              static_cast<unsigned long long>(r.complete_chunks), static_cast<unsigned long long>(r.rejected_chunks),
              static_cast<unsigned long long>(r.messages_recovered));
  for (const mcap::McapDiagnostic& d : reader.diagnostics()) {
    std::printf("diagnostic at %llu: %s\n", static_cast<unsigned long long>(d.offset), d.message.c_str());
  }
  bool ok = true;
  const auto fail = [&ok](const std::string& why) {
    std::printf("FAIL %s\n", why.c_str());
    ok = false;
  };
  if (!r.header_present) fail("no Header");
  if (r.rejected_chunks != 0) fail(std::to_string(r.rejected_chunks) + " chunk(s) rejected");
  if (cli.given("--expect-footer") && (expect_footer == "1") != r.footer_present) {
    fail(std::string("footer ") + (r.footer_present ? "present" : "missing"));
  }
  std::uint64_t in_chunks = 0;
  for (const mcap::McapChunkInfo& c : reader.chunks()) {
    if (!c.valid) fail("chunk at " + std::to_string(c.offset) + " not valid");
    in_chunks += c.message_count;
  }
  if (!reader.chunks().empty() && in_chunks != reader.messages().size()) {
    fail("chunks hold " + std::to_string(in_chunks) + " messages, read " + std::to_string(reader.messages().size()));
  }
  if (r.messages_recovered != reader.messages().size()) fail("messages_recovered differs from the messages read");
  // Every diagnostic must be about the end of the file (the cut), none about
  // anything before it.
  for (const mcap::McapDiagnostic& d : reader.diagnostics()) {
    if (d.offset < r.valid_bytes) fail("diagnostic before the cut: " + d.message);
  }

  const mcap::McapChannel* channel = reader.find_channel(topic);
  std::vector<std::uint64_t> seqs;
  if (channel == nullptr) {
    fail("no channel '" + topic + "'");
  } else {
    for (const mcap::McapMessage& m : reader.messages()) {
      if (m.channel_id == channel->id) seqs.push_back(m.sequence);
    }
  }
  const log_tool::SequenceReport seq = log_tool::analyze_sequence(seqs);
  std::printf("%s: %s\n", topic.c_str(), log_tool::describe(seq).c_str());
  if (!seq.complete() || seq.backwards != 0) fail(topic + ": not seq 1..K in order");
  const std::uint64_t recovered = seqs.size();
  std::printf("recovered %s %llu\n", topic.c_str(), static_cast<unsigned long long>(recovered));
  if (cli.given("--sent")) {
    std::printf("sent before the kill %llu, recovered %llu, lost %lld (bound %llu)\n",
                static_cast<unsigned long long>(sent), static_cast<unsigned long long>(recovered),
                static_cast<long long>(sent) - static_cast<long long>(recovered),
                static_cast<unsigned long long>(max_loss));
    if (static_cast<double>(recovered) + max_loss < sent) fail("lost more than the bound");
    if (recovered == 0) fail("nothing recovered");
  }
  std::printf("%s\n", ok ? "OK" : "FAILED");
  return ok ? 0 : 1;
}

}  // namespace
}  // namespace pixyslam

int main(int argc, char** argv) {
  return pixyslam::app::run_main("mcap_recovery_check", [&] { return pixyslam::run(argc, argv); });
}
