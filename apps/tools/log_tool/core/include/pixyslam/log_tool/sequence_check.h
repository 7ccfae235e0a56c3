#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace pixyslam::log_tool {

// An inclusive range of sequence numbers.
struct SequenceRange {
  std::uint64_t first = 0;
  std::uint64_t last = 0;
};

// What a stream of header sequence numbers (1, 2, 3, ... per writer) looks like.
struct SequenceReport {
  std::uint64_t count = 0;     // numbers given, duplicates included
  std::uint64_t distinct = 0;  // different numbers
  std::uint64_t min = 0;       // 0 when count == 0
  std::uint64_t max = 0;
  std::uint64_t missing = 0;     // numbers in [1, max] never given
  std::uint64_t duplicates = 0;  // count - distinct
  std::uint64_t zeros = 0;       // times 0 (not a valid seq) was given
  std::uint64_t backwards = 0;   // numbers smaller than the one given before them
  std::vector<SequenceRange> missing_ranges;   // the first `max_listed`, ascending
  std::vector<std::uint64_t> duplicated;       // the first `max_listed` numbers given twice or more

  // Exactly 1..count, each once (order not considered); true for an empty stream.
  bool complete() const { return missing == 0 && duplicates == 0 && zeros == 0; }
};

// Analyses `seqs` in arrival order. Pure; O(n log n).
SequenceReport analyze_sequence(const std::vector<std::uint64_t>& seqs, std::size_t max_listed = 8);

// One line, e.g. "seq 1..500" or "seq 1..500: 3 missing (5-7), 1 duplicate (9), 2 out of order".
std::string describe(const SequenceReport& report);

}  // namespace pixyslam::log_tool
