#include "ontime/util/json_input.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "ontime/util/error.hpp"

namespace ontime {
namespace {

using Json = nlohmann::json;
using OrderedJson = nlohmann::ordered_json;

// The InputError that parsing `text` raises (a test failure, and an empty error, if none).
template <class J>
InputError parse_error_of(const std::string& text) {
  try {
    detail::parse_json_strict<J>(text, "deep.json");
  } catch (const InputError& error) {
    return error;
  }
  ADD_FAILURE() << "parsed";
  return InputError("", "", "");
}

std::string nested(std::size_t depth, char open, const std::string& inner, char close) {
  return std::string(depth, open) + inner + std::string(depth, close);
}

TEST(JsonInput, NestingBeyondTheLimitIsRefusedAtTheFirstContainerTooDeep) {
  // 300,000 '[' (unclosed): the parser stops at the 257th, before any walk of the document.
  for (const std::string& text : {std::string(300'000, '['), nested(300'000, '[', "1", ']')}) {
    const InputError error = parse_error_of<Json>(text);
    EXPECT_EQ(error.source(), "deep.json");
    EXPECT_EQ(error.place(), "line 1, column 257");
    EXPECT_EQ(error.rule(),
              "invalid JSON: arrays and objects nested more than 256 levels deep (the limit of OnTime's "
              "files)");
  }
  // Objects count as arrays do, strings holding brackets do not, and the place is the line's.
  std::string objects = "{\"a\": \"[[[{{{\",\n \"b\": ";
  for (int i = 0; i < 300; ++i) objects += "{\"k\": ";
  const InputError error = parse_error_of<OrderedJson>(objects);
  EXPECT_EQ(error.place(), "line 2, column " + std::to_string(7 + 255 * 6));
  EXPECT_NE(error.rule().find("more than 256 levels"), std::string::npos);
}

TEST(JsonInput, NestingUpToTheLimitIsRead) {
  const Json deepest = detail::parse_json_strict<Json>(nested(detail::kMaxJsonDepth, '[', "7", ']'), "deep.json");
  const Json* inner = &deepest;
  for (std::size_t level = 1; level < detail::kMaxJsonDepth; ++level) inner = &(*inner)[0];
  EXPECT_EQ((*inner)[0], 7);
  EXPECT_EQ(parse_error_of<Json>(nested(detail::kMaxJsonDepth + 1, '[', "7", ']')).place(), "line 1, column 257");
}

TEST(JsonInput, ALineOfJsonLinesTooDeepIsNamedByItsLine) {
  const std::string text = "{\"a\": 1}\n" + nested(5'000, '[', "", ']') + "\n";
  try {
    detail::for_each_json_line<Json>(text, "log.jsonl", [](const Json&, std::size_t) {});
    ADD_FAILURE() << "read";
  } catch (const InputError& error) {
    EXPECT_EQ(error.place(), "line 2, column 257");
    EXPECT_NE(error.rule().find("nested more than 256 levels"), std::string::npos);
  }
}

TEST(JsonInput, AQuotedValueIsCutToABoundedLength) {
  EXPECT_EQ(detail::quote_json(Json(1.5)), "1.5");
  EXPECT_EQ(detail::quote_json(Json("cup")), "\"cup\"");
  EXPECT_EQ(detail::quote_json(Json::parse(R"([1, {"a": [2, [3]]}])")), "[1, {\"a\": [...]}]");
  EXPECT_EQ(detail::quote_json(Json::array()), "[]");
  EXPECT_EQ(detail::quote_json(Json(std::string(1'000'000, 'x'))), "\"" + std::string(79, 'x') + "...");
  // Built in code, beyond any parse limit: quoting does not walk it.
  Json deep = Json::array();
  for (int i = 0; i < 100'000; ++i) deep = Json::array({std::move(deep)});
  EXPECT_EQ(detail::quote_json(deep), "[[[...]]]");
  const std::string wide = detail::quote_json(Json(std::vector<int>(1'000'000, 12345)));
  EXPECT_EQ(wide.size(), 83u);
  EXPECT_EQ(wide.substr(0, 14), "[12345, 12345,");
  EXPECT_EQ(wide.substr(80), "...");
}

}  // namespace
}  // namespace ontime
