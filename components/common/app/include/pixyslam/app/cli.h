#pragma once

// The command line of every pixyslam executable: CLI11 (Debian libcli11-dev)
// behind one small interface, compiled once (cli.cpp: CLI11 is header-only
// and costs ~15 s per file that includes it). One flag name per meaning
// (docs/tools.md) and the same exit codes everywhere: 0 ok (and after
// --help), 1 runtime failure, 2 usage or configuration error.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace pixyslam::app {

// A command-line mistake (unknown or repeated flag, missing value, not a
// number): run_main() exits with 2, as for a config error.
class UsageError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// Runs f(); a std::invalid_argument it throws (a value checked outside Cli) becomes a UsageError.
template <class F>
void check_usage(F&& f) {
  try {
    f();
  } catch (const UsageError&) {
    throw;
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

class Cli {
 public:
  // One declared option; its methods refine it and return it.
  class Option {
   public:
    explicit Option(CLI::Option* option) : option_(option) {}
    Option& required();
    Option& existing_file();  // a config: missing or unreadable exits 2
    // A data file the program reads: one that does not exist or cannot be
    // read exits 1 from parse() ("<name>: PATH: cannot open: REASON").
    Option& input_file();
    Option& range(double min, double max);  // INT in [min - max] in --help for an int option
    Option& seed();                         // an integer in [0, parameters::kMaxSeed]
    Option& non_negative();
    Option& positive();  // a finite number > 0
    Option& choices(const std::vector<std::string>& allowed);
    Option& needs(Option& other);  // given only together with `other`
    Option& excludes(Option& other);  // never given together with `other`
    Option& type(const std::string& name);  // the value's name in --help, e.g. "DIR"

   private:
    friend class Cli;
    CLI::Option* option_;
    bool integer_ = false;  // declared on an int (or uint64) member
    bool input_ = false;    // input_file()
  };

  Cli(const std::string& name, const std::string& description);
  ~Cli();
  Cli(const Cli&) = delete;
  Cli& operator=(const Cli&) = delete;

  // "--name" is a flag with a value; a name without dashes is positional.
  Option& option(const std::string& name, std::string& value, const std::string& help);
  Option& option(const std::string& name, double& value, const std::string& help);
  Option& option(const std::string& name, int& value, const std::string& help);
  Option& option(const std::string& name, std::uint64_t& value, const std::string& help);
  Option& option(const std::string& name, std::vector<std::string>& values, const std::string& help);
  // Calls `each` with every value given (repeatable).
  Option& option_each(const std::string& name, std::function<void(const std::string&)> each, const std::string& help);
  // Calls `set` with the value (given at most once).
  Option& option_call(const std::string& name, std::function<void(const std::string&)> set, const std::string& help);
  void flag(const std::string& name, bool& value, const std::string& help);
  void footer(const std::string& text);
  bool given(const std::string& name) const;

  // A subcommand ("pixyslam_spy echo ..."): its own options and --help; the
  // parent then needs exactly one. chosen() after parse(): it was the one given.
  Cli& subcommand(const std::string& name, const std::string& description);
  bool chosen() const;

  // Returns the exit status when the process is to end here: 0 after --help
  // (the help on stdout), 2 for a usage error ("<name>: <what> (see --help)"
  // on stderr; unknown options are named before a missing required one), 1
  // for an input_file() that cannot be read; nothing when it is to go on.
  std::optional<int> parse(int argc, char** argv);

 private:
  explicit Cli(CLI::App* subcommand);
  Option& keep(CLI::Option* option);
  std::optional<int> check_inputs(const std::string& program) const;
  std::unique_ptr<CLI::App> owned_;  // the top level owns the CLI11 app; a subcommand does not
  CLI::App* app_;
  std::vector<std::unique_ptr<Option>> options_;
  std::vector<std::unique_ptr<Cli>> subcommands_;
};

// --config FILE: the process's YAML (must exist).
Cli::Option& add_config(Cli& cli, std::string& path, const std::string& help);

// --set KEY=VALUE, repeatable, or several comma-separated ("a=1,b=2"; a comma
// not followed by KEY= stays in the value: dds.interfaces=10.0.0.1,10.0.0.2).
// `example` shows a key, e.g. "filter.particles=300".
Cli::Option& add_set(Cli& cli, std::vector<std::string>& assignments, const std::string& example);

// --domain N, at most once: "dds.domain_id=N" appended to
// `dds_overrides` for dds::resolve_settings (the range is checked there, once).
Cli::Option& add_domain(Cli& cli, std::vector<std::string>& dds_overrides);

// --verbose: the long form of what a process prints at start (the effective configuration).
void add_verbose(Cli& cli, bool& verbose);

// "1, 2,10_000": comma-separated integers (blanks around an item and '_'
// between two digits allowed, empty items skipped), each at least `min`;
// UsageError naming `flag` for a bad item ("1 2") or an empty list.
std::vector<int> parse_int_list(const std::string& text, const std::string& flag, int min);

// "a=1,b=2,c" split into assignments at commas followed by KEY=.
std::vector<std::string> split_assignments(const std::string& text);

}  // namespace pixyslam::app
