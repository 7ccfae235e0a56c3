#include "pixyslam/app/cli.h"

#include <cstdio>

namespace pixyslam::app {

std::optional<int> parse(CLI::App& cli, int argc, char** argv) {
  try {
    cli.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::fputs(cli.help().c_str(), stdout);
    return 0;
  } catch (const CLI::CallForAllHelp&) {
    std::fputs(cli.help("", CLI::AppFormatMode::All).c_str(), stdout);
    return 0;
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "%s: %s (see --help)\n", cli.get_name().c_str(), e.what());
    return 2;
  }
  return std::nullopt;
}

CLI::Option* add_config(CLI::App& cli, std::string& path, const std::string& help) {
  return cli.add_option("--config", path, help)->required()->check(CLI::ExistingFile)->type_name("FILE");
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

CLI::Option* add_set(CLI::App& cli, std::vector<std::string>& assignments, const std::string& example) {
  return cli
      .add_option_function<std::vector<std::string>>(
          "--set",
          [&assignments](const std::vector<std::string>& values) {
            for (const std::string& v : values) {
              for (std::string& a : split_assignments(v)) assignments.push_back(std::move(a));
            }
          },
          "override a parameter of the config, e.g. --set " + example + " (repeatable; the list: --help)")
      ->type_name("KEY=VALUE")
      ->allow_extra_args(false);
}

CLI::Option* add_verbose(CLI::App& cli, bool& verbose) {
  return cli.add_flag("--verbose", verbose, "print the whole effective configuration at start");
}

}  // namespace pixyslam::app
