// libFuzzer target: arbitrary bytes as an MCAP file. The reader must either
// refuse it with std::runtime_error (not MCAP at all) or recover what it can,
// with consistent accounting (recovery and damage report), and never crash or
// read out of bounds.

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "fuzz_common.h"
#include "pixyslam/mcap/mcap_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const pixyslam::mcap::McapReader reader(std::vector<std::uint8_t>(data, data + size), "fuzz.mcap");
    const pixyslam::mcap::McapRecovery& r = reader.recovery();
    FUZZ_CHECK(r.file_size == size);
    FUZZ_CHECK(r.valid_bytes <= size);
    FUZZ_CHECK(r.valid_bytes + r.bytes_ignored_at_end == size);
    FUZZ_CHECK(r.messages_recovered == reader.messages().size());
    // The damage report: complete exactly when clean, ranges inside the file
    // and adding up, nothing damaged in a file only cut short.
    const pixyslam::mcap::McapDamage& d = reader.damage();
    FUZZ_CHECK((d.state == pixyslam::mcap::McapFileState::kComplete) == reader.clean());
    FUZZ_CHECK(d.intact_until <= size);
    std::uint64_t skipped = 0;
    std::uint64_t previous_end = 0;
    for (const pixyslam::mcap::McapByteRange& range : d.skipped) {
      FUZZ_CHECK(range.begin < range.end && range.end <= size && range.begin >= previous_end);
      previous_end = range.end;
      skipped += range.end - range.begin;
    }
    FUZZ_CHECK(skipped == d.bytes_skipped);
    for (const pixyslam::mcap::McapDamagedRecord& record : d.records) FUZZ_CHECK(record.end <= size);
    if (d.state == pixyslam::mcap::McapFileState::kNotClosed) {
      FUZZ_CHECK(d.records.empty() && d.skipped.empty() && !r.footer_present);
    }
    for (const pixyslam::mcap::McapMessage& m : reader.messages()) {
      (void)reader.find_channel(m.channel_id);  // a message may name an unknown channel: no crash
    }
    (void)reader.diagnostics_text();
  } catch (const std::runtime_error&) {
    // Not MCAP (no leading magic, or shorter than it): refused with a message.
  }
  return 0;
}
