#pragma once
// Command-line options shared by every settle command that takes a move: parsing into a
// core::MoveRequest, and reporting a bad request the same way everywhere (exit 2, one line on
// stderr naming the parameter, or a JSON error object with --json).
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "settle/core/planner.hpp"

namespace settle::cli {

// --key value pairs and bare --flags, checked against the options a command knows.
class Args {
 public:
  // value_options take one argument; flag_options take none.
  Args(int argc, char** argv, const std::set<std::string>& value_options, const std::set<std::string>& flag_options);

  [[nodiscard]] bool ok() const { return error_.empty(); }
  [[nodiscard]] const std::string& error() const { return error_; }
  [[nodiscard]] const std::string& error_param() const { return error_param_; }
  [[nodiscard]] bool flag(const std::string& name) const { return flags_.count(name) != 0; }
  [[nodiscard]] std::optional<std::string> get(const std::string& name) const;
  // All values of a repeatable option, in order.
  [[nodiscard]] std::vector<std::string> all(const std::string& name) const;

 private:
  std::multimap<std::string, std::string> values_;
  std::set<std::string> flags_;
  std::string error_;
  std::string error_param_;
};

struct RequestError {
  std::string code;     // a core::Status code or a CLI code such as "bad_number"
  std::string param;    // the offending option, e.g. "--time"
  std::string message;  // one sentence
};

// The options every move-taking command understands.
extern const std::set<std::string> kMoveValueOptions;
extern const std::set<std::string> kMoveFlagOptions;

// Fills `req` from the parsed options; false (with `err` set) on a malformed value.
[[nodiscard]] bool parse_move_request(const Args& args, core::MoveRequest& req, RequestError& err);
// Plans the request; on failure fills `err` naming the parameter the status is about.
[[nodiscard]] bool plan_move(const core::MoveRequest& req, core::Move<double>& out, RequestError& err);
// Parses one number (accepting nan/inf so that core can name them), false if not a number.
[[nodiscard]] bool parse_double(const std::string& s, double& out);
[[nodiscard]] bool parse_list(const std::string& s, std::vector<double>& out);
// Reads option `name` as a number into `out`; when it is absent `out` keeps its default. False,
// with `err` naming the option, when the value is not a number.
[[nodiscard]] bool read_number(const Args& args, const char* name, double& out, RequestError& err);

// Prints the error (stderr line, or JSON on stdout when json is set) and returns exit status 2.
int report_bad_request(const RequestError& err, bool json);

}  // namespace settle::cli
