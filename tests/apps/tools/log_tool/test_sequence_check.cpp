// The sequence check of `pixyslam_log check`: gaps, duplicates and counts of
// the header seq numbers of one topic (pure).
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/log_tool/sequence_check.h"

namespace pixyslam::log_tool {
namespace {

// ---------------------------------------------------------------- sequences

TEST(SequenceCheck, OneToNInAnyOrderIsComplete) {
  const SequenceReport r = analyze_sequence({3, 1, 2, 4, 5});
  EXPECT_TRUE(r.complete());
  EXPECT_EQ(r.count, 5u);
  EXPECT_EQ(r.min, 1u);
  EXPECT_EQ(r.max, 5u);
  EXPECT_EQ(r.backwards, 1u);  // 1 after 3
  EXPECT_EQ(describe(r), "seq 1..5: 1 out of order");
  EXPECT_EQ(describe(analyze_sequence({1, 2, 3})), "seq 1..3");
}

TEST(SequenceCheck, EmptyStreamIsComplete) {
  const SequenceReport r = analyze_sequence({});
  EXPECT_TRUE(r.complete());
  EXPECT_EQ(describe(r), "no messages");
}

TEST(SequenceCheck, GapsAndDuplicatesAreCountedAndListed) {
  // Missing 1 (a late start), 5-7 and 10; 8 twice, 9 three times.
  const SequenceReport r = analyze_sequence({2, 3, 4, 8, 8, 9, 9, 9, 11});
  EXPECT_FALSE(r.complete());
  EXPECT_EQ(r.missing, 5u);
  ASSERT_EQ(r.missing_ranges.size(), 3u);
  EXPECT_EQ(r.missing_ranges[0].first, 1u);
  EXPECT_EQ(r.missing_ranges[0].last, 1u);
  EXPECT_EQ(r.missing_ranges[1].first, 5u);
  EXPECT_EQ(r.missing_ranges[1].last, 7u);
  EXPECT_EQ(r.duplicates, 3u);
  EXPECT_EQ(r.duplicated, (std::vector<std::uint64_t>{8, 9}));
  EXPECT_EQ(r.distinct, 6u);
  EXPECT_EQ(describe(r), "seq 2..11: 5 missing (1, 5-7, 10), 3 duplicates (8, 9)");
}

TEST(SequenceCheck, ZeroIsNotAValidSeq) {
  const SequenceReport r = analyze_sequence({0, 1, 2});
  EXPECT_FALSE(r.complete());
  EXPECT_EQ(r.zeros, 1u);
  EXPECT_EQ(r.missing, 0u);
  EXPECT_EQ(describe(r), "seq 0..2: 1 with seq 0");
}

TEST(SequenceCheck, ListsAreBoundedButCountsAreNot) {
  std::vector<std::uint64_t> seqs;
  for (std::uint64_t s = 2; s <= 40; s += 2) seqs.push_back(s);  // every odd number missing
  const SequenceReport r = analyze_sequence(seqs, 3);
  EXPECT_EQ(r.missing, 20u);
  EXPECT_EQ(r.missing_ranges.size(), 3u);
  EXPECT_EQ(describe(r), "seq 2..40: 20 missing (1, 3, 5, ...)");
}

}  // namespace
}  // namespace pixyslam::log_tool
