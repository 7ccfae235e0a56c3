#pragma once

// One declaration per parameter: a table beside an options struct gives, for
// every member, its key path below the struct's YAML section, kind, range,
// unit, default and help text. Range checks, the effective configuration,
// `--set path=value` overrides and the help text all come from the table
// (YAML reading: pixyslam/config/parameters_yaml.h). Pure (std only).
#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cmath>
#include <cstdint>
#include <functional>
#include <iomanip>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace pixyslam::parameters {

// A value a range or a rule between parameters refuses, naming the parameter
// to blame: `path` below `section`, `reason` as "value V is ...". what() is
// "<section>.<path>: <reason>"; a YAML reader reports it on the key.
class RuleError : public std::invalid_argument {
 public:
  RuleError(const std::string& section, std::string path, std::string reason)
      : std::invalid_argument(section + "." + path + ": " + reason), path_(std::move(path)), reason_(std::move(reason)) {}
  const std::string& path() const { return path_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string path_;
  std::string reason_;
};

enum class Kind { kReal, kInteger, kBoolean, kChoice, kText, kList };

template <class Options>
struct Parameter {
  std::string path;  // below the section, mappings joined by '.': "motion.v_sigma_m_per_sqrt_s"
  Kind kind = Kind::kReal;
  double min = 0.0, max = 0.0;              // kReal, kInteger: inclusive range
  std::vector<std::string> choices;         // kChoice
  std::string unit;                         // "m/sqrt(s)"; empty for none
  std::string help;
  // The member, as a number (kReal, kInteger, kBoolean: 0 / 1) or a choice's name.
  std::function<double(const Options&)> get;
  std::function<void(Options&, double)> set;
  // kChoice, kText: the text; kList: the items joined by ','.
  std::function<std::string(const Options&)> get_choice;
  std::function<void(Options&, const std::string&)> set_choice;
  // kText, kList: throws std::invalid_argument saying why a value (each item
  // of a list) is not allowed; empty: any text.
  std::function<void(const std::string&)> check;
  bool required = false;  // the YAML must give it (required())
  // Its former path (renamed()): a YAML file that still uses it is read, with
  // a warning; --set with it is refused, naming the new path.
  std::string old_path;
};

template <class Options>
using Table = std::vector<Parameter<Options>>;

// A byte-count bound for a std::size_t parameter: 4 GiB, or the most a 32-bit
// size_t holds (armhf, where std::size_t{1} << 32 is 0).
inline constexpr std::size_t kMaxBytes4GiB =
    static_cast<std::size_t>(std::min<std::uint64_t>(std::uint64_t{1} << 32, std::numeric_limits<std::size_t>::max()));

// ---- Declaring: one call per member.

template <class Options>
Parameter<Options> real(std::string path, double min, double max, std::string unit, std::string help,
                        std::function<double&(Options&)> member) {
  Parameter<Options> p{std::move(path), Kind::kReal, min, max, {}, std::move(unit), std::move(help),
                       {}, {}, {}, {}, {}, false, {}};
  p.get = [member](const Options& o) { return member(const_cast<Options&>(o)); };
  p.set = [member](Options& o, double v) { member(o) = v; };
  return p;
}

// Integers up to 2^53 (exact in a double).
template <class Options, class Int>
Parameter<Options> integer(std::string path, Int min, Int max, std::string unit, std::string help,
                           std::function<Int&(Options&)> member) {
  Parameter<Options> p{std::move(path), Kind::kInteger, static_cast<double>(min), static_cast<double>(max), {},
                       std::move(unit), std::move(help), {}, {}, {}, {}, {}, false, {}};
  p.get = [member](const Options& o) { return static_cast<double>(member(const_cast<Options&>(o))); };
  p.set = [member](Options& o, double v) { member(o) = static_cast<Int>(v); };
  return p;
}

template <class Options>
Parameter<Options> boolean(std::string path, std::string help, std::function<bool&(Options&)> member) {
  Parameter<Options> p{std::move(path), Kind::kBoolean, 0.0, 1.0, {}, "", std::move(help),
                       {}, {}, {}, {}, {}, false, {}};
  p.get = [member](const Options& o) { return member(const_cast<Options&>(o)) ? 1.0 : 0.0; };
  p.set = [member](Options& o, double v) { member(o) = v != 0.0; };
  return p;
}

// Every random seed of the project is in [0, kMaxSeed] (2^53: exact in a
// double, so YAML, the command line and JSON carry it unchanged).
constexpr std::uint64_t kMaxSeed = std::uint64_t{1} << 53;

// An enum given by name: `names` pairs each value with its YAML text.
template <class Options, class Enum>
Parameter<Options> choice(std::string path, std::vector<std::pair<std::string, Enum>> names, std::string help,
                          std::function<Enum&(Options&)> member) {
  Parameter<Options> p{std::move(path), Kind::kChoice, 0.0, 0.0, {}, "", std::move(help),
                       {}, {}, {}, {}, {}, false, {}};
  for (const auto& n : names) p.choices.push_back(n.first);
  p.get_choice = [member, names](const Options& o) {
    for (const auto& n : names) {
      if (n.second == member(const_cast<Options&>(o))) return n.first;
    }
    return std::string("?");
  };
  p.set_choice = [member, names](Options& o, const std::string& text) {
    for (const auto& n : names) {
      if (n.first == text) {
        member(o) = n.second;
        return;
      }
    }
    throw std::invalid_argument("not one of the choices");
  };
  return p;
}

// Free text (a name, a file); `check` (may be empty) refuses bad values.
template <class Options>
Parameter<Options> text(std::string path, std::string help, std::function<std::string&(Options&)> member,
                        std::function<void(const std::string&)> check = {}) {
  Parameter<Options> p{std::move(path), Kind::kText, 0.0, 0.0, {}, "", std::move(help),
                       {}, {}, {}, {}, std::move(check), false, {}};
  p.get_choice = [member](const Options& o) { return member(const_cast<Options&>(o)); };
  p.set_choice = [member](Options& o, const std::string& v) { member(o) = v; };
  return p;
}

// "a, b,,c" -> {"a", "b", "c"}: comma-separated items, blanks around them
// trimmed, empty ones dropped.
inline std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> items;
  std::string::size_type start = 0;
  while (start <= text.size()) {
    const auto comma = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, comma - start);
    const auto first = item.find_first_not_of(" \t");
    if (first != std::string::npos) items.push_back(item.substr(first, item.find_last_not_of(" \t") - first + 1));
    start = comma + 1;
  }
  return items;
}

// "1, 2,10_000": comma-separated integers (blanks around an item and '_'
// between two digits allowed, empty items skipped), each at least `min`;
// std::invalid_argument naming `what` for a bad item ("1 2") or an empty list.
inline std::vector<int> parse_int_list(const std::string& text, const std::string& what, int min) {
  std::vector<int> out;
  for (const std::string& item : split_list(text)) {
    std::string digits;
    bool ok = true;
    for (std::size_t i = 0; i < item.size(); ++i) {
      const char c = item[i];
      if (c == '_' && i > 0 && i + 1 < item.size() && std::isdigit(static_cast<unsigned char>(item[i - 1])) &&
          std::isdigit(static_cast<unsigned char>(item[i + 1]))) {
        continue;
      }
      if (!std::isdigit(static_cast<unsigned char>(c)) && !(i == 0 && c == '-')) ok = false;
      digits += c;
    }
    char* end = nullptr;
    const long v = ok ? std::strtol(digits.c_str(), &end, 10) : 0;
    if (!ok || digits.empty() || *end != '\0' || v < min || v > std::numeric_limits<int>::max()) {
      throw std::invalid_argument(what + ": '" + item + "' is not an integer >= " + std::to_string(min));
    }
    out.push_back(static_cast<int>(v));
  }
  if (out.empty()) throw std::invalid_argument(what + ": no value in '" + text + "'");
  return out;
}

// A list of texts: a YAML sequence, or comma-separated on a command line or
// in the environment; `check` (may be empty) refuses a bad item.
template <class Options>
Parameter<Options> list(std::string path, std::string help, std::function<std::vector<std::string>&(Options&)> member,
                        std::function<void(const std::string&)> check = {}) {
  Parameter<Options> p{std::move(path), Kind::kList, 0.0, 0.0, {}, "", std::move(help),
                       {}, {}, {}, {}, std::move(check), false, {}};
  p.get_choice = [member](const Options& o) {
    std::string joined;
    for (const std::string& item : member(const_cast<Options&>(o))) joined += (joined.empty() ? "" : ",") + item;
    return joined;
  };
  p.set_choice = [member](Options& o, const std::string& v) { member(o) = split_list(v); };
  return p;
}

// The same parameter, to be given in every YAML file.
template <class Options>
Parameter<Options> required(Parameter<Options> p) {
  p.required = true;
  return p;
}

// The parameter was called `old_path` (in the same mapping) before.
template <class Options>
Parameter<Options> renamed(Parameter<Options> p, std::string old_path) {
  p.old_path = std::move(old_path);
  return p;
}

// ---- Using the table.

// The whole of `text` as a finite number, or nothing.
inline std::optional<double> parse_number(const std::string& text) {
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used == 0 || used != text.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

inline std::string number_text(double v) {
  std::ostringstream os;
  if (std::isfinite(v) && v == std::floor(v) && std::abs(v) <= 9007199254740992.0) {
    os << static_cast<long long>(v);  // whole numbers in full
  } else {
    os << std::setprecision(15) << v;
  }
  return os.str();
}

template <class Options>
std::string range_text(const Parameter<Options>& p) {
  if (p.kind == Kind::kChoice) {
    std::string list;
    for (const std::string& c : p.choices) list += (list.empty() ? "" : " | ") + c;
    return list;
  }
  if (p.kind == Kind::kBoolean) return "true | false";
  if (p.kind == Kind::kText) return "text";
  if (p.kind == Kind::kList) return "list";
  return "[" + number_text(p.min) + ", " + number_text(p.max) + "]";
}

// The member's value as YAML text.
template <class Options>
std::string value_text(const Parameter<Options>& p, const Options& o) {
  switch (p.kind) {
    case Kind::kChoice: return p.get_choice(o);
    case Kind::kText: {
      std::string quoted = "'";  // YAML single quotes: a quote doubled
      for (const char c : p.get_choice(o)) quoted += c == '\'' ? std::string("''") : std::string(1, c);
      return quoted + "'";
    }
    case Kind::kList: return "[" + p.get_choice(o) + "]";
    case Kind::kBoolean: return p.get(o) != 0.0 ? "true" : "false";
    default: return number_text(p.get(o));
  }
}

// A kText / kList member through its check (each item of a list).
template <class Options>
void check_text(const Parameter<Options>& p, const Options& o) {
  if (!p.check) return;
  if (p.kind == Kind::kText) {
    p.check(p.get_choice(o));
    return;
  }
  for (const std::string& item : split_list(p.get_choice(o))) p.check(item);
}

// Every number within its range, every text through its check; throws
// RuleError "<section>.<path>: value V is out of range [min, max] <unit>"
// (or "value 'T' is <the check's reason>").
template <class Options>
void check_ranges(const Options& o, const Table<Options>& table, const std::string& section) {
  for (const Parameter<Options>& p : table) {
    if (p.kind == Kind::kText || p.kind == Kind::kList) {
      try {
        check_text(p, o);
      } catch (const std::invalid_argument& e) {
        throw RuleError(section, p.path, "value " + value_text(p, o) + " is " + e.what());
      }
      continue;
    }
    if (p.kind != Kind::kReal && p.kind != Kind::kInteger) continue;
    const double v = p.get(o);
    if (std::isfinite(v) && v >= p.min && v <= p.max) continue;
    throw RuleError(section, p.path,
                    "value " + number_text(v) + " is out of range " + range_text(p) + (p.unit.empty() ? "" : " " + p.unit));
  }
}

template <class Options>
const Parameter<Options>* find(const Table<Options>& table, const std::string& path) {
  for (const Parameter<Options>& p : table) {
    if (p.path == path) return &p;
  }
  return nullptr;
}

// Sets the parameter at `path` from text (a number, true/false, or a choice's
// name), checking its range; throws std::invalid_argument naming the path.
template <class Options>
void set_from_text(Options& o, const Table<Options>& table, const std::string& section, const std::string& path,
                   const std::string& text) {
  const Parameter<Options>* p = find(table, path);
  const std::string name = section + "." + path;
  if (p == nullptr) {
    for (const Parameter<Options>& q : table) {
      if (!q.old_path.empty() && q.old_path == path) {
        throw std::invalid_argument("'" + name + "' was renamed '" + section + "." + q.path + "'");
      }
    }
    throw std::invalid_argument("unknown parameter '" + name + "'");
  }
  const auto fail = [&](const std::string& why) {
    throw std::invalid_argument(name + " = '" + text + "': " + why + " (" + range_text(*p) +
                                (p->unit.empty() ? "" : " " + p->unit) + ")");
  };
  switch (p->kind) {
    case Kind::kChoice:
      try {
        p->set_choice(o, text);
      } catch (const std::invalid_argument&) {
        fail("not one of the choices");
      }
      return;
    case Kind::kText:
    case Kind::kList: {
      Options trial = o;
      p->set_choice(trial, text);
      if (p->check) {
        try {
          check_text(*p, trial);
        } catch (const std::invalid_argument& e) {
          throw std::invalid_argument(name + " = '" + text + "': " + e.what());
        }
      }
      o = std::move(trial);
      return;
    }
    case Kind::kBoolean:
      if (text != "true" && text != "false") fail("not true or false");
      p->set(o, text == "true" ? 1.0 : 0.0);
      return;
    default: {
      const std::optional<double> parsed = parse_number(text);
      if (!parsed) fail("not a number");
      const double v = *parsed;
      if (p->kind == Kind::kInteger && v != std::floor(v)) fail("not an integer");
      if (v < p->min || v > p->max) fail("out of range");
      p->set(o, v);
    }
  }
}

// The assignments of `section` ("section.KEY=V"), moved out of `assignments`
// (the others stay, in order): for a process whose --set reaches several sections.
inline std::vector<std::string> take_section(std::vector<std::string>& assignments, const std::string& section) {
  std::vector<std::string> taken, rest;
  for (std::string& a : assignments) (a.rfind(section + ".", 0) == 0 ? taken : rest).push_back(std::move(a));
  assignments = std::move(rest);
  return taken;
}

// "path=value": set_from_text for one override (e.g. from `--set`).
template <class Options>
void apply_override(Options& o, const Table<Options>& table, const std::string& section, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw std::invalid_argument("'" + assignment + "': expected KEY=VALUE, e.g. " + section + "." +
                                (table.empty() ? std::string("key") : table.front().path) + "=...");
  }
  std::string key = assignment.substr(0, eq);
  if (key.rfind(section + ".", 0) != 0) {
    throw std::invalid_argument("'" + key + "': not a parameter of '" + section + "'");
  }
  set_from_text(o, table, section, key.substr(section.size() + 1), assignment.substr(eq + 1));
}

// An override of one section whose keys two tables declare (one YAML mapping
// read into two structs): to `first` when it declares the key, else to `second`
// (which names a key neither declares).
template <class First, class Second>
void apply_override_to_either(First& first, const Table<First>& first_table, Second& second,
                              const Table<Second>& second_table, const std::string& section,
                              const std::string& assignment) {
  const std::string key = assignment.substr(0, assignment.find('='));
  const bool in_section = key.rfind(section + ".", 0) == 0;
  if (in_section && find(first_table, key.substr(section.size() + 1)) != nullptr) {
    apply_override(first, first_table, section, assignment);
  } else {
    apply_override(second, second_table, section, assignment);
  }
}

// The section as YAML (nested mappings, each value with its unit as a comment).
template <class Options>
std::string to_yaml(const Options& o, const Table<Options>& table, const std::string& section) {
  std::ostringstream os;
  os << section << ":\n";
  std::vector<std::string> open;  // mappings opened so far, outermost first
  for (const Parameter<Options>& p : table) {
    std::vector<std::string> parts;
    std::string rest = p.path;
    for (auto dot = rest.find('.'); dot != std::string::npos; dot = rest.find('.')) {
      parts.push_back(rest.substr(0, dot));
      rest = rest.substr(dot + 1);
    }
    std::size_t common = 0;
    while (common < open.size() && common < parts.size() && open[common] == parts[common]) ++common;
    open.resize(common);
    for (std::size_t i = common; i < parts.size(); ++i) {
      os << std::string(2 * (i + 1), ' ') << parts[i] << ":\n";
      open.push_back(parts[i]);
    }
    os << std::string(2 * (parts.size() + 1), ' ') << rest << ": " << value_text(p, o);
    if (!p.unit.empty()) os << "  # " << p.unit;
    os << "\n";
  }
  return os.str();
}

// One line per parameter: key, range and unit, default, help.
template <class Options>
std::string help_text(const Table<Options>& table, const std::string& section, const Options& defaults = Options{}) {
  std::ostringstream os;
  for (const Parameter<Options>& p : table) {
    os << "  " << section << "." << p.path << "  " << range_text(p) << (p.unit.empty() ? "" : " " + p.unit)
       << (p.required ? std::string(", required") : ", default " + value_text(p, defaults)) << "\n      " << p.help
       << "\n";
  }
  return os.str();
}

}  // namespace pixyslam::parameters
