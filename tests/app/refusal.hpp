// SPDX-License-Identifier: Apache-2.0
#pragma once
// A refused command line as the CLI contract wants it: exit 2, nothing on stdout, one stderr line
// naming the option; with --json only the error object naming the same option (and code). Shared
// by the CLI suites that list bad cases.
#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>

#include "run_cli.hpp"

namespace settle::test {

struct Case {
  std::string args;
  std::string param;  // the option the error must name
  std::string code;   // "" = any
};

inline void expect_refused(const Case& c) {
  SCOPED_TRACE(c.args);
  const CliResult text = run_cli(c.args);
  EXPECT_EQ(text.status, 2) << text.out;
  EXPECT_TRUE(text.stdout_text.empty()) << "nothing on stdout on exit 2: " << text.stdout_text;
  EXPECT_EQ(std::count(text.stderr_text.begin(), text.stderr_text.end(), '\n'), 1) << text.stderr_text;
  // The option named is the one given: "settle: error: --node: ..." (or "... option --x ...").
  EXPECT_NE(text.stderr_text.find(c.param + ":"), std::string::npos) << text.stderr_text;
  const CliResult json = run_cli(c.args + " --json");
  EXPECT_EQ(json.status, 2) << json.out;
  const auto j = nlohmann::json::parse(json.stdout_text, nullptr, false);
  ASSERT_FALSE(j.is_discarded()) << json.stdout_text;
  EXPECT_EQ(j.at("status"), "error");
  EXPECT_EQ(j.at("parameter"), c.param) << json.stdout_text;
  if (!c.code.empty()) {
    EXPECT_EQ(j.at("error"), c.code) << json.stdout_text;
  }
  EXPECT_FALSE(j.at("message").get<std::string>().empty());
  EXPECT_EQ(std::count(json.stdout_text.begin(), json.stdout_text.end(), '\n'), 1) << json.stdout_text;
}

}  // namespace settle::test
