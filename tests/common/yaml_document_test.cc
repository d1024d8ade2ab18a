#include "ccsrm/common/yaml_document.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "ccsrm/common/error.h"
#include "ccsrm/common/number_text.h"

namespace ccsrm {
namespace {

using ::testing::HasSubstr;

std::string ErrorOf(const std::string& text) {
  try {
    ParseYamlDocument(text, "f.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ParseYamlDocument, ReadsAGoodDocument) {
  const YAML::Node root = ParseYamlDocument("a: 1\nb:\n  - {c: 2, d: 3}\n  - c: 4\n", "f.yaml");
  EXPECT_EQ(root["a"].as<int>(), 1);
  EXPECT_EQ(root["b"][1]["c"].as<int>(), 4);
}

TEST(ParseYamlDocument, AcceptsTheSameKeyInDifferentMappings) {
  EXPECT_EQ(ErrorOf("a: {x: 1}\nb: {x: 2}\nc:\n  - x: 1\n  - x: 2\n"), "");
}

TEST(ParseYamlDocument, RefusesATopLevelDuplicateNamingBothLines) {
  EXPECT_EQ(ErrorOf("solver:\n  x: 1\nother: 2\nsolver:\n  x: 3\n"),
            "f.yaml: line 4, key 'solver': duplicate key (first at line 1)");
}

TEST(ParseYamlDocument, RefusesADuplicateInsideASequenceItem) {
  const std::string text =
      "arm:\n"
      "  segments:\n"
      "    - name: one\n"
      "      link_mass_kg: 0.095\n"
      "      links: 6\n"
      "      link_mass_kg: 0.2\n";
  EXPECT_EQ(ErrorOf(text),
            "f.yaml: line 6, key 'arm.segments[0].link_mass_kg': duplicate key (first at line 4)");
}

TEST(ParseYamlDocument, RefusesADuplicateInAFlowMappingOfALaterItem) {
  EXPECT_EQ(ErrorOf("cables:\n  - {segment: 1, hole_angle_deg: 0}\n"
                    "  - {segment: 2, segment: 1}\n"),
            "f.yaml: line 3, key 'cables[1].segment': duplicate key (first at line 3)");
}

TEST(ParseYamlDocument, RefusesADuplicateInsideNestedSequences) {
  EXPECT_THAT(ErrorOf("- - {a: 1}\n  - {a: 1, a: 2}\n"), HasSubstr("key '[0][1].a'"));
}

TEST(ParseYamlDocument, AliasesAreWalkedOnceAndTerminate) {
  // The alias repeats the anchored mapping: no duplicate there.
  EXPECT_EQ(ErrorOf("base: &b {x: 1, y: 2}\nother: *b\nlist: [*b, *b]\n"), "");
  EXPECT_THAT(ErrorOf("base: &b {x: 1, x: 2}\nother: *b\n"),
              HasSubstr("line 1, key 'base.x': duplicate key (first at line 1)"));
}

TEST(ParseYamlDocument, ReportsASyntaxErrorWithItsLine) {
  const std::string error = ErrorOf("a: 1\nb: [1, 2\n");
  EXPECT_THAT(error, HasSubstr("f.yaml: line "));
  EXPECT_THAT(error, HasSubstr("YAML syntax error: "));
  EXPECT_EQ(error.find('\n'), std::string::npos);
}

TEST(ParseYamlDocument, AcceptsEmptyAndScalarDocuments) {
  EXPECT_TRUE(ParseYamlDocument("", "f.yaml").IsNull());
  EXPECT_EQ(ParseYamlDocument("42", "f.yaml").as<int>(), 42);
}

TEST(ParseNumberText, ReadsFiniteDoublesAndNamesWhatElseIsWrong) {
  double value = -1.0;
  EXPECT_EQ(ParseNumberText("2.6e10", &value), "");
  EXPECT_EQ(value, 2.6e10);
  EXPECT_EQ(ParseNumberText("0", &value), "");
  EXPECT_EQ(value, 0.0);
  EXPECT_EQ(ParseNumberText("1e-300", &value), "");  // small but a normal double
  EXPECT_EQ(ParseNumberText("0.1x", &value), kNotANumber);
  EXPECT_EQ(ParseNumberText("", &value), kNotANumber);
  EXPECT_EQ(ParseNumberText(" 1", &value), kNotANumber);
  EXPECT_EQ(ParseNumberText("1e400", &value),
            "is outside the range of a double (magnitude above 1.8e+308)");
  EXPECT_EQ(ParseNumberText("-1e400", &value),
            "is outside the range of a double (magnitude above 1.8e+308)");
  EXPECT_EQ(ParseNumberText("1e-400", &value),
            "underflows: it is nearer 0 than a double can hold (2.2e-308); write 0 if 0 is meant");
  for (const char* text : {"nan", "inf", "-inf", ".nan", ".inf", "-.inf", ".NaN"}) {
    EXPECT_EQ(ParseNumberText(text, &value), "is not a finite number") << text;
  }
  EXPECT_EQ(value, 1e-300);  // untouched by the failures
}

TEST(ReadYamlNumber, NamesTheFieldAndTheText) {
  const YAML::Node root = ParseYamlDocument("a: 1.5\nb: heavy\nc: [1]\nd: 1e999\n", "f.yaml");
  EXPECT_EQ(ReadYamlNumber(root["a"], "f.yaml", "key 'a'"), 1.5);
  const auto error = [&](const char* key) {
    try {
      ReadYamlNumber(root[key], "f.yaml", std::string("key '") + key + "'");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error("b"), "f.yaml: key 'b': expected a number, found 'heavy'");
  EXPECT_EQ(error("c"), "f.yaml: key 'c': expected a number");
  EXPECT_THAT(error("d"), HasSubstr("f.yaml: key 'd': '1e999' is outside the range of a double"));
}

}  // namespace
}  // namespace ccsrm
