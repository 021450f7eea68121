// Strict JSON text: keys written twice are errors naming their path, syntax errors say where.
#include "io/json_text.h"

#include <gtest/gtest.h>

#include "common/error.h"

namespace topopt::io {
namespace {

std::string message_of(const std::string& text, ErrorCode code) {
  try {
    parse_json_text(text, "job file");
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), code) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "no error for " << text;
  return "";
}

TEST(JsonText, ParsesWhatNlohmannParses) {
  const auto j = parse_json_text(R"({"a": [1, {"b": 2}, [3, {"b": 4}]], "c": {"b": 5}})", "x");
  EXPECT_EQ(j["a"][1]["b"], 2);
  EXPECT_EQ(j["c"]["b"], 5);  // the same key in different objects is fine
}

TEST(JsonText, KeysWrittenTwiceAreNamedWithTheirPath) {
  EXPECT_NE(message_of(R"({"a": 1, "a": 2})", ErrorCode::InvalidParameter).find("the key 'a' appears twice;"),
            std::string::npos);
  const std::string m = message_of(R"({"a": [1, {"b": 2}, [3, {"b": 4, "b": 5}]]})", ErrorCode::InvalidParameter);
  EXPECT_NE(m.find("the key 'b' appears twice in 'a[2][1]'"), std::string::npos) << m;
}

TEST(JsonText, SyntaxErrorsSayLineAndColumn) {
  const std::string m = message_of("{\n  \"a\": 1,\n  \"b\": ]\n}", ErrorCode::Io);
  EXPECT_NE(m.find("job file is not valid JSON at line 3, column 8"), std::string::npos) << m;
  EXPECT_EQ(m.find("json.exception"), std::string::npos) << m;  // not the library's internals
}

}  // namespace
}  // namespace topopt::io
