// Tests of config::YamlReader: typed access, defaults, required keys, unknown-key
// detection, strict scalar parsing, and hostile files (directories, FIFOs, oversize
// files, duplicate keys).

#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/config/parameters_yaml.h"
#include "pixyslam/config/yaml_reader.h"
#include "temp_dir.h"

namespace pixyslam::config {
namespace {

// Runs `f`, expects a ConfigError and returns its message ("" if none was thrown).
template <class F>
std::string config_error_of(F&& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected ConfigError";
  return "";
}

TEST(YamlReader, ReadsTypedValues) {
  YamlReader r = YamlReader::from_string(
      "n: 2.5\n"
      "i: -42\n"
      "b: true\n"
      "f: false\n"
      "s: hello\n"
      "c: beta\n",
      "typed.yaml");
  EXPECT_DOUBLE_EQ(r.number("n", 0.0, 10.0), 2.5);
  EXPECT_EQ(r.integer("i", -100, 100), -42);
  EXPECT_TRUE(r.boolean("b"));
  EXPECT_FALSE(r.boolean("f"));
  EXPECT_EQ(r.text("s"), "hello");
  EXPECT_EQ(r.choice("c", {"alpha", "beta"}), "beta");
  EXPECT_NO_THROW(r.finish());
}

TEST(YamlReader, AbsentKeysGiveTheFallback) {
  // Given an empty document, when every accessor is given a fallback,
  // then the fallbacks come back and finish() is satisfied.
  YamlReader r = YamlReader::from_string("", "empty.yaml");
  EXPECT_FALSE(r.has("x"));
  EXPECT_DOUBLE_EQ(r.number("x", 0.0, 1.0, 0.25), 0.25);
  EXPECT_EQ(r.integer("k", 0, 10, 7), 7);
  EXPECT_TRUE(r.boolean("b", true));
  EXPECT_FALSE(r.boolean("b2", false));
  EXPECT_EQ(r.text("s", "dflt"), "dflt");
  EXPECT_EQ(r.choice("c", {"a", "b"}, "b"), "b");
  EXPECT_NO_THROW(r.finish());
}

TEST(YamlReader, PresentKeyOverridesTheFallback) {
  YamlReader r = YamlReader::from_string("x: 0.75\nk: 3\n", "o.yaml");
  EXPECT_DOUBLE_EQ(r.number("x", 0.0, 1.0, 0.25), 0.75);
  EXPECT_EQ(r.integer("k", 0, 10, 7), 3);
}

TEST(YamlReader, RequiredKeysMissingNameTheKey) {
  YamlReader r = YamlReader::from_string("other: 1\n", "req.yaml");
  const std::string m1 = config_error_of([&] { r.number("speed", 0.0, 1.0); });
  EXPECT_NE(m1.find("req.yaml"), std::string::npos) << m1;
  EXPECT_NE(m1.find("'speed'"), std::string::npos) << m1;
  EXPECT_NE(m1.find("missing"), std::string::npos) << m1;
  const std::string m2 = config_error_of([&] { r.child("sub"); });
  EXPECT_NE(m2.find("'sub'"), std::string::npos) << m2;
  const std::string m3 = config_error_of([&] { r.integer("count", 0, 3); });
  EXPECT_NE(m3.find("'count'"), std::string::npos) << m3;
  const std::string m4 = config_error_of([&] { r.boolean("flag"); });
  EXPECT_NE(m4.find("'flag'"), std::string::npos) << m4;
}

TEST(YamlReader, ChildOfWrongShapeIsAnError) {
  YamlReader r = YamlReader::from_string("sub: 3\nlist: [1, 2]\n", "shape.yaml");
  const std::string m = config_error_of([&] { r.child("sub"); });
  EXPECT_NE(m.find("'sub'"), std::string::npos) << m;
  EXPECT_NE(m.find("mapping"), std::string::npos) << m;
  const std::string m2 = config_error_of([&] { r.number("list", 0.0, 5.0); });
  EXPECT_NE(m2.find("'list'"), std::string::npos) << m2;
}

TEST(YamlReader, FinishDetectsUnknownKeyAtTopLevel) {
  YamlReader r = YamlReader::from_string("known: 1\ntypo: 2\n", "top.yaml");
  EXPECT_EQ(r.integer("known", 0, 5), 1);
  const std::string m = config_error_of([&] { r.finish(); });
  EXPECT_NE(m.find("top.yaml"), std::string::npos) << m;
  EXPECT_NE(m.find("'typo'"), std::string::npos) << m;
  EXPECT_NE(m.find("unknown"), std::string::npos) << m;
}

TEST(YamlReader, FinishDetectsUnknownKeyInNestedChildWithFullPath) {
  // Given a nested mapping with one misspelt key two levels down,
  YamlReader root = YamlReader::from_string(
      "outer:\n"
      "  inner:\n"
      "    good: 1\n"
      "    speeed: 2\n",
      "nested.yaml");
  YamlReader outer = root.child("outer");
  YamlReader inner = outer.child("inner");
  EXPECT_EQ(inner.path(), "outer.inner");
  EXPECT_EQ(inner.origin(), "nested.yaml");
  EXPECT_EQ(inner.integer("good", 0, 5), 1);
  // then the inner finish() names the full dotted path of the typo,
  const std::string m = config_error_of([&] { inner.finish(); });
  EXPECT_NE(m.find("nested.yaml"), std::string::npos) << m;
  EXPECT_NE(m.find("'outer.inner.speeed'"), std::string::npos) << m;
  // while the parents, whose keys were all read, are satisfied.
  EXPECT_NO_THROW(outer.finish());
  EXPECT_NO_THROW(root.finish());
}

TEST(YamlReader, FinishOnParentFlagsAnUnreadChildMapping) {
  YamlReader root = YamlReader::from_string("a: 1\nsection:\n  x: 1\n", "p.yaml");
  EXPECT_EQ(root.integer("a", 0, 5), 1);
  // has() alone does not count as reading the key.
  EXPECT_TRUE(root.has("section"));
  const std::string m = config_error_of([&] { root.finish(); });
  EXPECT_NE(m.find("'section'"), std::string::npos) << m;
}

TEST(YamlReader, IntegerRejectsFractionsAndText) {
  YamlReader r = YamlReader::from_string("a: 1.5\nb: abc\nc: 12x\nd: \"\"\ne: 1e3\n", "int.yaml");
  for (const char* key : {"a", "b", "c", "d", "e"}) {
    const std::string m = config_error_of([&] { r.integer(key, -1000000, 1000000); });
    EXPECT_NE(m.find(std::string("'") + key + "'"), std::string::npos) << m;
    EXPECT_NE(m.find("integer"), std::string::npos) << m;
  }
}

TEST(YamlReader, IntegerAcceptsNegativeAndChecksRange) {
  YamlReader r = YamlReader::from_string("a: -7\nb: 11\n", "range.yaml");
  EXPECT_EQ(r.integer("a", -10, 10), -7);
  const std::string m = config_error_of([&] { r.integer("b", 0, 10); });
  EXPECT_NE(m.find("'b'"), std::string::npos) << m;
  EXPECT_NE(m.find("out of range"), std::string::npos) << m;
  EXPECT_NE(m.find("[0, 10]"), std::string::npos) << m;
}

TEST(YamlReader, NumberRejectsTextNonFiniteAndOutOfRange) {
  YamlReader r = YamlReader::from_string("a: abc\nb: .nan\nc: 1e999\nd: 2.5\ne: -0.1\nf: 3e-1\n", "num.yaml");
  for (const char* key : {"a", "b", "c"}) {
    const std::string m = config_error_of([&] { r.number(key, -1e9, 1e9); });
    EXPECT_NE(m.find(std::string("'") + key + "'"), std::string::npos) << m;
  }
  const std::string m = config_error_of([&] { r.number("d", 0.0, 1.0); });
  EXPECT_NE(m.find("out of range"), std::string::npos) << m;
  EXPECT_THROW(r.number("e", 0.0, 1.0), ConfigError);
  EXPECT_DOUBLE_EQ(r.number("f", 0.0, 1.0), 0.3);
}

TEST(YamlReader, BooleanAcceptsOnlyTrueAndFalse) {
  YamlReader r = YamlReader::from_string("a: yes\nb: 1\nc: on\nd: true\ne: false\n", "bool.yaml");
  for (const char* key : {"a", "b", "c"}) {
    const std::string m = config_error_of([&] { r.boolean(key); });
    EXPECT_NE(m.find(std::string("'") + key + "'"), std::string::npos) << m;
    EXPECT_NE(m.find("true or false"), std::string::npos) << m;
  }
  EXPECT_TRUE(r.boolean("d"));
  EXPECT_FALSE(r.boolean("e"));
}

TEST(YamlReader, ChoiceListsTheAllowedValues) {
  YamlReader r = YamlReader::from_string("mode: foo\n", "choice.yaml");
  const std::string m = config_error_of([&] { r.choice("mode", {"alpha", "beta"}); });
  EXPECT_NE(m.find("'mode'"), std::string::npos) << m;
  EXPECT_NE(m.find("foo"), std::string::npos) << m;
  EXPECT_NE(m.find("alpha"), std::string::npos) << m;
  EXPECT_NE(m.find("beta"), std::string::npos) << m;
}

TEST(YamlReader, SyntaxErrorNamesOriginAndLine) {
  // The flow sequence opened on line 3 is never closed (reported at the end).
  const std::string m = config_error_of([] {
    YamlReader::from_string("a: 1\nb: 2\nc: [1, 2\n", "broken.yaml");
  });
  EXPECT_NE(m.find("broken.yaml"), std::string::npos) << m;
  EXPECT_NE(m.find("line"), std::string::npos) << m;
}

TEST(YamlReader, SyntaxErrorReportsTheOffendingLineNumber) {
  // Line 4 is indented by one space: neither in the mapping of line 2 nor top level.
  const std::string m = config_error_of([] {
    YamlReader::from_string("a: 1\nb:\n  c: 2\n d: 3\n", "indent.yaml");
  });
  EXPECT_NE(m.find("indent.yaml"), std::string::npos) << m;
  EXPECT_NE(m.find("line 4"), std::string::npos) << m;
}

TEST(YamlReader, TopLevelMustBeAMapping) {
  const std::string m = config_error_of([] { YamlReader::from_string("- 1\n- 2\n", "list.yaml"); });
  EXPECT_NE(m.find("list.yaml"), std::string::npos) << m;
}

TEST(YamlReader, MissingFileIsAConfigError) {
  const std::string m =
      config_error_of([] { YamlReader::from_file("/nonexistent/dir/pixyslam_no_such_file.yaml"); });
  EXPECT_NE(m.find("pixyslam_no_such_file.yaml"), std::string::npos) << m;
}

}  // namespace
}  // namespace pixyslam::config

namespace pixyslam::config {
namespace {

// Found by fuzz_yaml_options: a mapping used as a key ("? a: 1") made finish()
// throw yaml-cpp's BadConversion instead of a ConfigError.
TEST(YamlReader, NonScalarKeyIsAConfigErrorNamingTheLine) {
  YamlReader root = YamlReader::from_string("filter:\n  particles: 5\n  ? neff: 0.6\n", "complex_key.yaml");
  YamlReader filter = root.child("filter");
  EXPECT_EQ(filter.integer("particles", 1, 10, 1), 5);
  try {
    filter.finish();
    FAIL() << "finish() accepted a mapping as a key";
  } catch (const ConfigError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("complex_key.yaml"), std::string::npos) << m;
    EXPECT_NE(m.find("line 3"), std::string::npos) << m;
  }
  EXPECT_THROW(filter.keys(), ConfigError);
}

}  // namespace
}  // namespace pixyslam::config

// Issue 18 (hostile or unlucky config input): every problem is a ConfigError
// naming the file, never a crash or a silently ignored setting.
namespace pixyslam::config {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Was: yaml-cpp read the directory through an ifstream and std::ios_base::failure
// escaped (encoder_bridge, pixy_bridge and logger aborted, exit 134).
TEST(YamlReaderFiles, DirectoryIsAConfigErrorNamingIt) {
  const test::TempDir dir;
  const std::string m = config_error_of([&] { YamlReader::from_file(dir.path()); });
  EXPECT_TRUE(contains(m, dir.path() + ": not a regular file")) << m;
  EXPECT_TRUE(contains(m, "directory")) << m;
  const std::string t = config_error_of([&] { read_config_text(dir.path()); });
  EXPECT_TRUE(contains(t, dir.path() + ": not a regular file")) << t;
}

// Was: YAML::LoadFile opened the FIFO and waited for a writer for ever.
TEST(YamlReaderFiles, FifoIsRejectedWithoutWaitingForAWriter) {
  const test::TempDir dir;
  const std::string fifo = dir.path() + "/config.yaml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string m = config_error_of([&] { YamlReader::from_file(fifo); });
  EXPECT_TRUE(contains(m, fifo + ": not a regular file")) << m;
}

// Was: no limit (48 MB of YAML took 4 GB of memory).
TEST(YamlReaderFiles, FileOverTheSizeLimitIsRejectedBeforeParsing) {
  const test::TempDir dir;
  // A comment padded to exactly the limit still loads,
  std::string text = "a: 1\n#";
  text += std::string(kMaxConfigFileBytes - text.size() - 1, 'x') + "\n";
  ASSERT_EQ(text.size(), kMaxConfigFileBytes);
  const std::string at_limit = dir.write("at_limit.yaml", text);
  EXPECT_EQ(YamlReader::from_file(at_limit).integer("a", 0, 5), 1);
  // one byte more does not: the message names the file and both sizes.
  const std::string over = dir.write("over.yaml", text + "\n");
  const std::string m = config_error_of([&] { YamlReader::from_file(over); });
  EXPECT_TRUE(contains(m, over + ": file is " + std::to_string(kMaxConfigFileBytes + 1) + " bytes")) << m;
  EXPECT_TRUE(contains(m, std::to_string(kMaxConfigFileBytes))) << m;
  // A caller with bigger files (checkpoints) passes its own limit.
  EXPECT_EQ(YamlReader::from_file(over, 2 * kMaxConfigFileBytes).integer("a", 0, 5), 1);
}

TEST(YamlReaderFiles, MissingFileNamesTheFileAndTheReason) {
  const std::string m = config_error_of([] { YamlReader::from_file("/nonexistent/dir/pixyslam_missing.yaml"); });
  EXPECT_TRUE(contains(m, "/nonexistent/dir/pixyslam_missing.yaml: cannot open file")) << m;
  EXPECT_TRUE(contains(m, "No such file")) << m;
}

// Was: accepted, the first value won (yaml-cpp keeps both; a lookup finds the first).
TEST(YamlReaderDuplicates, DuplicateScalarKeyNamesKeyAndBothLines) {
  const std::string m = config_error_of([] {
    YamlReader::from_string("filter:\n  particles: 100\n  seed: 1\n  particles: 500\n", "dup.yaml");
  });
  EXPECT_TRUE(contains(m, "dup.yaml: key 'filter.particles': duplicate at line 4 (first at line 2)")) << m;
}

TEST(YamlReaderDuplicates, DuplicateSectionIsAnError) {
  const std::string m = config_error_of([] {
    YamlReader::from_string(
        "filter:\n"
        "  particles: 100\n"
        "estimator:\n"
        "  status_period_s: 5\n"
        "filter:\n"
        "  seed: 7\n",
        "sections.yaml");
  });
  EXPECT_TRUE(contains(m, "sections.yaml: key 'filter': duplicate at line 5 (first at line 1)")) << m;
}

TEST(YamlReaderDuplicates, DuplicateInANestedMappingOfAFileNamesFilePathAndBothLines) {
  const test::TempDir dir;
  const std::string path = dir.write("nested.yaml",
                                    "a: 1\n"
                                    "outer:\n"
                                    "  inner:\n"
                                    "    x: 1\n"
                                    "    y: 2\n"
                                    "    # a comment\n"
                                    "    x: 3\n");
  const std::string m = config_error_of([&] { YamlReader::from_file(path); });
  EXPECT_TRUE(contains(m, path + ": key 'outer.inner.x': duplicate at line 7 (first at line 4)")) << m;
}

TEST(YamlReaderDuplicates, DuplicateInAListItemAndOnOneLine) {
  const std::string m = config_error_of([] {
    YamlReader::from_string("processes:\n  - {name: a}\n  - {name: b, delay_s: 1, name: c}\n", "list.yaml");
  });
  EXPECT_TRUE(contains(m, "key 'processes[1].name': duplicate at line 3, column 27 (first at line 3, column 6)"))
      << m;
}

TEST(YamlReaderDuplicates, SameKeyInDifferentMappingsAndAliasesAreFine) {
  YamlReader r = YamlReader::from_string(
      "a: {x: 1}\n"
      "b: {x: 2}\n"
      "c: &shared {x: 3}\n"
      "d: *shared\n"
      "e: [*shared, *shared]\n",
      "ok.yaml");
  EXPECT_EQ(r.child("d").integer("x", 0, 5), 3);
}

// A misspelt key with no value (null) is as unknown as one with a value.
TEST(YamlReaderUnknownKeys, NullValuedTypoIsAnUnknownKey) {
  for (const char* value : {"", " ~", " null"}) {
    YamlReader top = YamlReader::from_string(std::string("known: 1\ntypo:") + value + "\n", "null_top.yaml");
    EXPECT_EQ(top.integer("known", 0, 5), 1);
    const std::string m = config_error_of([&] { top.finish(); });
    EXPECT_TRUE(contains(m, "null_top.yaml: key 'typo': unknown key")) << value << ": " << m;

    YamlReader root =
        YamlReader::from_string(std::string("section:\n  typo:") + value + "\n  known: 2\n", "null_nested.yaml");
    YamlReader section = root.child("section");
    EXPECT_EQ(section.integer("known", 0, 5, 0), 2);
    EXPECT_EQ(section.number("other", 0.0, 1.0, 0.5), 0.5);  // absent optional keys do not excuse it
    const std::string n = config_error_of([&] { section.finish(); });
    EXPECT_TRUE(contains(n, "null_nested.yaml: key 'section.typo': unknown key")) << value << ": " << n;
  }
}

}  // namespace
}  // namespace pixyslam::config

namespace pixyslam::config {
namespace {

// ---- Parameter tables (pixyslam/parameters, read by config::read_parameters):
// texts, lists, required keys and rules reported on their key.
namespace table_test {

struct Options {
  std::string name = "robot1";
  std::vector<std::string> peers;
  double rate_hz = 10.0;
  double max_rate_hz = 12.0;
};

const parameters::Table<Options>& table() {
  using O = Options;
  namespace P = parameters;
  static const P::Table<O> t = {
      P::text<O>("name", "a name", [](O& o) -> std::string& { return o.name; },
                 [](const std::string& v) {
                   if (v.empty()) throw std::invalid_argument("empty");
                 }),
      P::list<O>("peers", "addresses", [](O& o) -> std::vector<std::string>& { return o.peers; },
                 [](const std::string& v) {
                   if (v.find('.') == std::string::npos) throw std::invalid_argument("not dotted");
                 }),
      P::required(P::real<O>("rate_hz", 0.1, 100.0, "Hz", "the rate", [](O& o) -> double& { return o.rate_hz; })),
      P::renamed(
          P::real<O>("max_rate_hz", 0.1, 1000.0, "Hz", "the most", [](O& o) -> double& { return o.max_rate_hz; }),
          "top_hz"),
  };
  return t;
}

void validate(const Options& o) {
  parameters::check_ranges(o, table(), "s");
  if (o.max_rate_hz < o.rate_hz) throw parameters::RuleError("s", "max_rate_hz", "value below rate_hz");
}

Options read(const std::string& yaml) {
  YamlReader root = YamlReader::from_string(yaml, "t.yaml");
  YamlReader s = root.child("s");
  Options o;
  read_parameters(s, table(), o);
  s.finish();
  check_rules(s, [&] { validate(o); });
  return o;
}

}  // namespace table_test

TEST(ParameterTable, ReadsTextsListsAndRequiredKeys) {
  const table_test::Options o = table_test::read("s:\n  name: r2\n  peers: [10.0.0.1, 10.0.0.2]\n  rate_hz: 5\n");
  EXPECT_EQ(o.name, "r2");
  EXPECT_EQ(o.peers, (std::vector<std::string>{"10.0.0.1", "10.0.0.2"}));
  EXPECT_EQ(o.rate_hz, 5.0);
  // The printed section reads back as the same values.
  const std::string printed = parameters::to_yaml(o, table_test::table(), "s");
  EXPECT_EQ(parameters::to_yaml(table_test::read(printed), table_test::table(), "s"), printed);
  EXPECT_NE(parameters::help_text(table_test::table(), "s").find("s.rate_hz  [0.1, 100] Hz, required"),
            std::string::npos);
}

TEST(ParameterTable, ErrorsNameTheKey) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"s:\n  name: r2\n", "key 's.rate_hz': missing"},
      {"s:\n  rate_hz: 5\n  name: ''\n", "key 's.name': value '' is empty"},
      {"s:\n  rate_hz: 5\n  peers: [a, 10.0.0.1]\n", "key 's.peers': value [a,10.0.0.1] is not dotted"},
      {"s:\n  rate_hz: 500\n", "key 's.rate_hz': value 500 is out of range"},
      {"s:\n  rate_hz: 50\n  max_rate_hz: 20\n", "key 's.max_rate_hz': value below rate_hz"},
  };
  for (const auto& [yaml, expected] : cases) {
    const std::string e = config_error_of([&] { table_test::read(yaml); });
    EXPECT_NE(e.find("t.yaml: " + expected), std::string::npos) << "got: " << e << "\nfor:\n" << yaml;
  }
}

TEST(ParameterTable, OverridesFromTextCheckLikeTheFile) {
  table_test::Options o;
  parameters::apply_override(o, table_test::table(), "s", "s.peers=10.0.0.3, 10.0.0.4");
  EXPECT_EQ(o.peers, (std::vector<std::string>{"10.0.0.3", "10.0.0.4"}));
  parameters::apply_override(o, table_test::table(), "s", "s.name=it's");
  EXPECT_EQ(o.name, "it's");
  EXPECT_NE(parameters::to_yaml(o, table_test::table(), "s").find("name: 'it''s'"), std::string::npos);
  for (const char* bad : {"s.peers=nodots", "s.rate_hz=fast", "s.rate_hz=0", "s.colour=red", "other.rate_hz=1"}) {
    table_test::Options before = o;
    EXPECT_THROW(parameters::apply_override(o, table_test::table(), "s", bad), std::invalid_argument) << bad;
    EXPECT_EQ(o.peers, before.peers) << bad;  // unchanged after a refused value
  }
}

// A renamed key: a file with the old name is read (the warning names the file
// and both keys), one with both is refused, and --set with the old name is
// refused naming the new one.
TEST(ParameterTable, ARenamedKeyIsStillReadFromFilesButNotFromOverrides) {
  testing::internal::CaptureStderr();
  const table_test::Options o = table_test::read("s:\n  rate_hz: 5\n  top_hz: 50\n");
  const std::string warning = testing::internal::GetCapturedStderr();
  EXPECT_EQ(o.max_rate_hz, 50.0);
  EXPECT_NE(warning.find("t.yaml: key 's.top_hz' is deprecated: it was renamed 's.max_rate_hz'"), std::string::npos)
      << warning;
  EXPECT_NE(config_error_of([] { table_test::read("s:\n  rate_hz: 5\n  top_hz: 50\n  max_rate_hz: 40\n"); })
                .find("t.yaml: key 's.top_hz': renamed 's.max_rate_hz', which is given too"),
            std::string::npos);
  EXPECT_NE(config_error_of([] { table_test::read("s:\n  rate_hz: 5\n  top_hz: 500000\n"); })
                .find("t.yaml: key 's.top_hz': value 500000 is out of range"),
            std::string::npos);
  table_test::Options over;
  try {
    parameters::apply_override(over, table_test::table(), "s", "s.top_hz=20");
    ADD_FAILURE() << "the old name was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "'s.top_hz' was renamed 's.max_rate_hz'");
  }
  EXPECT_EQ(over.max_rate_hz, 12.0);
}

}  // namespace
}  // namespace pixyslam::config
