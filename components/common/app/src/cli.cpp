#include "pixyslam/app/cli.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include <CLI/CLI.hpp>

#include "pixyslam/app/process_main.h"
#include "pixyslam/dds/dds_options.h"
#include "pixyslam/parameters/parameters.h"

namespace pixyslam::app {

Cli::Option& Cli::Option::required() {
  option_->required();
  return *this;
}

Cli::Option& Cli::Option::existing_file() {
  CLI::Validator exists = CLI::ExistingFile;
  option_->check(exists.description(""));  // "--config FILE", not "FILE:FILE"
  return *this;
}

Cli::Option& Cli::Option::input_file() {
  input_ = true;
  return *this;
}

Cli::Option& Cli::Option::range(double min, double max) {
  if (integer_) {
    option_->check(CLI::Range(static_cast<std::int64_t>(min), static_cast<std::int64_t>(max)));
  } else {
    option_->check(CLI::Range(min, max));
  }
  return *this;
}

Cli::Option& Cli::Option::seed() {
  option_->check(CLI::Range(std::uint64_t{0}, parameters::kMaxSeed));
  return *this;
}

namespace {

// A number (the whole text) satisfying `ok`, else "must be <what>, got 'T'".
CLI::Validator number_check(bool (*ok)(double), const std::string& what) {
  return CLI::Validator(
      [ok, what](std::string& text) -> std::string {
        std::size_t used = 0;
        double v = std::nan("");
        try {
          v = std::stod(text, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        return used == text.size() && ok(v) ? std::string() : "must be a number " + what + ", got '" + text + "'";
      },
      what);
}

}  // namespace

Cli::Option& Cli::Option::non_negative() {
  option_->check(number_check([](double v) { return v >= 0.0 && std::isfinite(v); }, ">= 0"));
  return *this;
}

Cli::Option& Cli::Option::positive() {
  option_->check(number_check([](double v) { return v > 0.0 && std::isfinite(v); }, "> 0"));
  return *this;
}

Cli::Option& Cli::Option::choices(const std::vector<std::string>& allowed) {
  option_->check(CLI::IsMember(allowed));
  return *this;
}

Cli::Option& Cli::Option::excludes(Option& other) {
  option_->excludes(other.option_);
  return *this;
}

Cli::Option& Cli::Option::needs(Option& other) {
  option_->needs(other.option_);
  return *this;
}

Cli::Option& Cli::Option::type(const std::string& name) {
  option_->type_name(name);
  return *this;
}

Cli::Cli(const std::string& name, const std::string& description)
    : owned_(std::make_unique<CLI::App>(description, name)), app_(owned_.get()) {}

Cli::Cli(CLI::App* subcommand) : app_(subcommand) {}

Cli& Cli::subcommand(const std::string& name, const std::string& description) {
  app_->require_subcommand(1);
  subcommands_.push_back(std::unique_ptr<Cli>(new Cli(app_->add_subcommand(name, description))));
  return *subcommands_.back();
}

bool Cli::chosen() const { return app_->parsed(); }

Cli::~Cli() = default;

Cli::Option& Cli::keep(CLI::Option* option) {
  options_.push_back(std::make_unique<Option>(option));
  return *options_.back();
}

Cli::Option& Cli::option(const std::string& name, std::string& value, const std::string& help) {
  return keep(app_->add_option(name, value, help));
}

Cli::Option& Cli::option(const std::string& name, double& value, const std::string& help) {
  return keep(app_->add_option(name, value, help));
}

Cli::Option& Cli::option(const std::string& name, int& value, const std::string& help) {
  Option& o = keep(app_->add_option(name, value, help));
  o.integer_ = true;
  return o;
}

Cli::Option& Cli::option(const std::string& name, std::uint64_t& value, const std::string& help) {
  Option& o = keep(app_->add_option(name, value, help));
  o.integer_ = true;
  return o;
}

Cli::Option& Cli::option(const std::string& name, std::vector<std::string>& values, const std::string& help) {
  return keep(app_->add_option(name, values, help));
}

Cli::Option& Cli::option_each(const std::string& name, std::function<void(const std::string&)> each,
                              const std::string& help) {
  return keep(app_->add_option_function<std::vector<std::string>>(
                      name,
                      [each](const std::vector<std::string>& values) {
                        for (const std::string& v : values) each(v);
                      },
                      help)
                  ->allow_extra_args(false));
}

Cli::Option& Cli::option_call(const std::string& name, std::function<void(const std::string&)> set,
                              const std::string& help) {
  return keep(app_->add_option_function<std::string>(name, std::move(set), help));
}

void Cli::flag(const std::string& name, bool& value, const std::string& help) { app_->add_flag(name, value, help); }

void Cli::footer(const std::string& text) { app_->footer(text); }

bool Cli::given(const std::string& name) const { return app_->count(name) != 0; }

std::optional<int> Cli::check_inputs(const std::string& program) const {
  for (const auto& option : options_) {
    if (!option->input_ || option->option_->count() == 0) continue;
    for (const std::string& path : option->option_->results()) {
      try {
        check_input_file(path);
      } catch (const std::runtime_error& e) {
        std::fprintf(stderr, "%s: %s\n", program.c_str(), e.what());
        return 1;
      }
    }
  }
  for (const auto& sub : subcommands_) {
    if (!sub->chosen()) continue;
    if (const auto failed = sub->check_inputs(program)) return failed;
  }
  return std::nullopt;
}

std::optional<int> Cli::parse(int argc, char** argv) {
  try {
    app_->parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::fputs(app_->help().c_str(), stdout);  // a subcommand's own when it was given: "TOOL COMMAND --help"
    return 0;
  } catch (const CLI::CallForAllHelp&) {
    std::fputs(app_->help("", CLI::AppFormatMode::All).c_str(), stdout);
    return 0;
  } catch (const CLI::ParseError& e) {
    // A word where a subcommand was expected: name it and the choices.
    if (!subcommands_.empty() && app_->get_subcommands().empty() && argc > 1 && argv[1][0] != '-') {
      std::string names;
      for (const auto& sub : subcommands_) names += (names.empty() ? "" : ", ") + sub->app_->get_name();
      std::fprintf(stderr, "%s: unknown command '%s' (one of: %s; see --help)\n", app_->get_name().c_str(), argv[1],
                   names.c_str());
      return 2;
    }
    // CLI11 checks required options before unknown words: a misspelt
    // "--confg" would otherwise read "--config is required".
    std::string unknown;
    for (const std::string& word : app_->remaining(true)) {
      if (word.size() > 1 && word[0] == '-') unknown += (unknown.empty() ? "" : ", ") + word;
    }
    if (!unknown.empty() && dynamic_cast<const CLI::ExtrasError*>(&e) == nullptr) {
      std::fprintf(stderr, "%s: unknown option %s (see --help)\n", app_->get_name().c_str(), unknown.c_str());
      return 2;
    }
    std::fprintf(stderr, "%s: %s (see --help)\n", app_->get_name().c_str(), e.what());
    return 2;
  }
  return check_inputs(app_->get_name());
}

Cli::Option& add_config(Cli& cli, std::string& path, const std::string& help) {
  return cli.option("--config", path, help).required().existing_file().type("FILE");
}

std::vector<std::string> split_assignments(const std::string& text) {
  std::vector<std::string> out;
  std::string rest = text;
  while (!rest.empty()) {
    std::size_t cut = std::string::npos;
    for (std::size_t comma = rest.find(','); comma != std::string::npos; comma = rest.find(',', comma + 1)) {
      const std::size_t eq = rest.find('=', comma + 1);
      const std::size_t next = rest.find(',', comma + 1);
      if (eq != std::string::npos && (next == std::string::npos || eq < next)) {
        cut = comma;
        break;
      }
    }
    out.push_back(rest.substr(0, cut));
    rest = cut == std::string::npos ? std::string() : rest.substr(cut + 1);
  }
  return out;
}

Cli::Option& add_set(Cli& cli, std::vector<std::string>& assignments, const std::string& example) {
  return cli
      .option_each(
          "--set",
          [&assignments](const std::string& v) {
            for (std::string& a : split_assignments(v)) assignments.push_back(std::move(a));
          },
          "override a parameter of the config, e.g. --set " + example + " (repeatable; the list: --help)")
      .type("KEY=VALUE");
}

Cli::Option& add_domain(Cli& cli, std::vector<std::string>& dds_overrides) {
  return cli
      .option_call(
          "--domain", [&dds_overrides](const std::string& d) { dds_overrides.push_back(dds::domain_override(d)); },
          "DDS domain (overrides the config's and PIXYSLAM_DDS_DOMAIN)")
      .type("N");
}

void add_verbose(Cli& cli, bool& verbose) {
  cli.flag("--verbose", verbose, "print the whole effective configuration at start");
}

std::vector<int> parse_int_list(const std::string& text, const std::string& flag, int min) {
  std::vector<int> out;
  check_usage([&] { out = parameters::parse_int_list(text, flag, min); });
  return out;
}

}  // namespace pixyslam::app
