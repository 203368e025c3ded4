// A generated part of a document under docs/, between a begin and an end marker line, checked
// against what the code generates now; with SYNBENCH_REGENERATE_DOCS=1 the test rewrites it.
#pragma once

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace synbench::test {

inline std::string read_text_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline bool regenerate_docs() {
  const char* v = std::getenv("SYNBENCH_REGENERATE_DOCS");
  return v && std::string(v) == "1";
}

// `generated` is what belongs between the line `begin` and the line `end` of `path`.
inline void expect_generated_section(const std::string& path, const std::string& begin, const std::string& end,
                                     const std::string& generated) {
  std::string doc = read_text_file(path);
  const auto b = doc.find(begin);
  const auto e = doc.find(end);
  ASSERT_NE(b, std::string::npos) << path << " lacks the line " << begin;
  ASSERT_NE(e, std::string::npos) << path << " lacks the line " << end;
  ASSERT_LT(b, e);
  const std::size_t from = b + begin.size();
  const std::string current = doc.substr(from, e - from);
  if (regenerate_docs() && current != generated) {
    doc.replace(from, e - from, generated);
    std::ofstream(path) << doc;
    return;
  }
  EXPECT_EQ(current, generated) << path << " is stale; rerun this test with SYNBENCH_REGENERATE_DOCS=1 to rewrite it";
}

}  // namespace synbench::test
