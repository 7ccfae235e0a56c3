// Tests of config::YamlReader: typed access, defaults, required keys, unknown-key
// detection and strict scalar parsing.

#include <string>

#include <gtest/gtest.h>

#include "pixyslam/config/yaml_reader.h"

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
