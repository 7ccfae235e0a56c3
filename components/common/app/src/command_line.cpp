#include "pixyslam/app/command_line.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>

namespace pixyslam::app {

CommandLine::CommandLine(int argc, char** argv, const std::set<std::string>& known_flags) {
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "--help" || flag == "-h") {
      help_ = true;
      continue;
    }
    if (flag.rfind("--", 0) != 0 || known_flags.count(flag.substr(2)) == 0) {
      throw UsageError("unknown argument '" + flag + "'");
    }
    if (i + 1 >= argc) throw UsageError(flag + " needs a value");
    if (!values_.emplace(flag.substr(2), argv[++i]).second) {
      throw UsageError(flag + " given twice");
    }
  }
}

const std::string& CommandLine::get(const std::string& flag) const {
  auto it = values_.find(flag);
  if (it == values_.end()) throw UsageError("missing --" + flag);
  return it->second;
}

std::string CommandLine::get(const std::string& flag, const std::string& fallback) const {
  auto it = values_.find(flag);
  return it == values_.end() ? fallback : it->second;
}

double CommandLine::number(const std::string& flag, double fallback) const {
  auto it = values_.find(flag);
  if (it == values_.end()) return fallback;
  char* end = nullptr;
  const double v = std::strtod(it->second.c_str(), &end);
  if (it->second.empty() || *end != '\0') {
    throw UsageError("--" + flag + ": not a number: '" + it->second + "'");
  }
  return v;
}

void require_files(const std::vector<std::string>& files) {
  for (const std::string& f : files) {
    std::error_code ec;
    if (!std::filesystem::exists(f, ec)) throw UsageError(f + ": no such file");
  }
}

std::string folder_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

std::optional<int> usage_exit(const std::vector<std::string>& args, const char* usage) {
  if (args.empty()) {
    std::fputs(usage, stderr);
    return 2;
  }
  if (args[0] == "--help" || args[0] == "-h") {
    std::fputs(usage, stdout);
    return 0;
  }
  return std::nullopt;
}

}  // namespace pixyslam::app
