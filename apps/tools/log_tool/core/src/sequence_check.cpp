#include "pixyslam/log_tool/sequence_check.h"

#include <algorithm>
#include <sstream>

namespace pixyslam::log_tool {

SequenceReport analyze_sequence(const std::vector<std::uint64_t>& seqs, std::size_t max_listed) {
  SequenceReport r;
  r.count = seqs.size();
  for (std::size_t i = 1; i < seqs.size(); ++i) {
    if (seqs[i] < seqs[i - 1]) ++r.backwards;
  }
  std::vector<std::uint64_t> sorted = seqs;
  std::sort(sorted.begin(), sorted.end());
  std::uint64_t expected = 1;  // the next number that 1..max needs
  for (std::size_t i = 0; i < sorted.size(); ++i) {
    const std::uint64_t s = sorted[i];
    if (i > 0 && s == sorted[i - 1]) {
      if (r.duplicated.size() < max_listed && (r.duplicated.empty() || r.duplicated.back() != s)) {
        r.duplicated.push_back(s);
      }
      continue;
    }
    ++r.distinct;
    if (s == 0) continue;
    if (s > expected) {
      r.missing += s - expected;
      if (r.missing_ranges.size() < max_listed) r.missing_ranges.push_back({expected, s - 1});
    }
    expected = s + 1;
  }
  r.zeros = static_cast<std::uint64_t>(std::count(sorted.begin(), sorted.end(), std::uint64_t{0}));
  r.duplicates = r.count - r.distinct;
  if (!sorted.empty()) {
    r.min = sorted.front();
    r.max = sorted.back();
  }
  return r;
}

std::string describe(const SequenceReport& r) {
  std::ostringstream os;
  if (r.count == 0) return "no messages";
  os << "seq " << r.min << ".." << r.max;
  std::vector<std::string> problems;
  if (r.missing > 0) {
    std::ostringstream p;
    p << r.missing << " missing (";
    for (std::size_t i = 0; i < r.missing_ranges.size(); ++i) {
      const SequenceRange& g = r.missing_ranges[i];
      p << (i ? ", " : "") << g.first;
      if (g.last != g.first) p << "-" << g.last;
    }
    std::uint64_t listed = 0;
    for (const SequenceRange& g : r.missing_ranges) listed += g.last - g.first + 1;
    if (listed < r.missing) p << ", ...";
    p << ")";
    problems.push_back(p.str());
  }
  if (r.duplicates > 0) {
    std::ostringstream p;
    p << r.duplicates << (r.duplicates == 1 ? " duplicate (" : " duplicates (");
    for (std::size_t i = 0; i < r.duplicated.size(); ++i) p << (i ? ", " : "") << r.duplicated[i];
    p << ")";
    problems.push_back(p.str());
  }
  if (r.zeros > 0) problems.push_back(std::to_string(r.zeros) + " with seq 0");
  if (r.backwards > 0) problems.push_back(std::to_string(r.backwards) + " out of order");
  for (std::size_t i = 0; i < problems.size(); ++i) os << (i ? ", " : ": ") << problems[i];
  return os.str();
}

}  // namespace pixyslam::log_tool
