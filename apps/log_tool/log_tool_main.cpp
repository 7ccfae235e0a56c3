// pixyslam_log: inspect and check MCAP recordings of the logger.
//   pixyslam_log info FILE.mcap
//   pixyslam_log check FILE.mcap [--expect TOPIC=N ...] [--allow-recovered]
// info prints size, duration, per-topic counts, schemas, chunks and, for a
// truncated file, what was recovered. check decodes every message with the
// project's types and checks header seq 1..N per topic. Exit status: 0 ok,
// 1 check failed or file unreadable, 2 command-line error.
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "log_commands.h"

namespace {

constexpr const char* kUsage =
    "usage: pixyslam_log info FILE.mcap\n"
    "       pixyslam_log check FILE.mcap [--expect TOPIC=N ...] [--allow-recovered]\n";

// TOPIC=N, N a non-negative integer.
void add_expectation(const std::string& text, pixyslam::log_tool::CheckRequest& request) {
  const auto eq = text.rfind('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size()) {
    throw std::invalid_argument("--expect needs TOPIC=N, got '" + text + "'");
  }
  const std::string count = text.substr(eq + 1);
  if (count.find_first_not_of("0123456789") != std::string::npos || count.size() > 18) {
    throw std::invalid_argument("--expect " + text + ": N must be a non-negative integer");
  }
  if (!request.expected.emplace(text.substr(0, eq), std::stoull(count)).second) {
    throw std::invalid_argument("--expect given twice for '" + text.substr(0, eq) + "'");
  }
}

}  // namespace

int main(int argc, char** argv) {
  using namespace pixyslam;
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    std::fputs(kUsage, args.empty() ? stderr : stdout);
    return args.empty() ? 2 : 0;
  }
  const std::string& command = args[0];
  std::string path;
  log_tool::CheckRequest request;
  try {
    if (command != "info" && command != "check") throw std::invalid_argument("unknown command '" + command + "'");
    for (std::size_t i = 1; i < args.size(); ++i) {
      const std::string& a = args[i];
      if (command == "check" && a == "--expect") {
        if (i + 1 >= args.size()) throw std::invalid_argument("--expect needs a value");
        add_expectation(args[++i], request);
      } else if (command == "check" && a.rfind("--expect=", 0) == 0) {
        add_expectation(a.substr(9), request);
      } else if (command == "check" && a == "--allow-recovered") {
        request.allow_recovered = true;
      } else if (a.rfind("-", 0) == 0) {
        throw std::invalid_argument("unknown option '" + a + "' for " + command);
      } else if (path.empty()) {
        path = a;
      } else {
        throw std::invalid_argument("more than one file given");
      }
    }
    if (path.empty()) throw std::invalid_argument(command + " needs an MCAP file");
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "pixyslam_log: %s\n%s", e.what(), kUsage);
    return 2;
  }

  try {
    if (command == "info") return log_tool::run_info(path, std::cout);
    request.path = path;
    return log_tool::run_check(request, std::cout);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pixyslam_log: %s\n", e.what());
    return 1;
  }
}
