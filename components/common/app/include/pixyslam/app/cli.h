#pragma once

// The command line of every pixyslam executable: CLI11 (Debian libcli11-dev),
// one flag name per meaning (docs/tools.md) and the same exit codes
// everywhere: 0 ok (and after --help), 1 runtime failure, 2 usage or
// configuration error.
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace pixyslam::app {

// Parses argv with `cli`. Returns the exit status when the process is to end
// here: 0 after --help (the help on stdout), 2 for a usage error
// ("<name>: <what> (see --help)" on stderr); nothing when it is to go on.
std::optional<int> parse(CLI::App& cli, int argc, char** argv);

// --config FILE: the process's YAML (must exist).
CLI::Option* add_config(CLI::App& cli, std::string& path, const std::string& help);

// --set KEY=VALUE, repeatable, or several comma-separated ("a=1,b=2"; a comma
// not followed by KEY= stays in the value: dds.interfaces=10.0.0.1,10.0.0.2).
// `example` shows a key, e.g. "filter.particles=300".
CLI::Option* add_set(CLI::App& cli, std::vector<std::string>& assignments, const std::string& example);

// --verbose: the long form of what a process prints at start (the effective configuration).
CLI::Option* add_verbose(CLI::App& cli, bool& verbose);

// "a=1,b=2,c" split into assignments at commas followed by KEY=.
std::vector<std::string> split_assignments(const std::string& text);

}  // namespace pixyslam::app
