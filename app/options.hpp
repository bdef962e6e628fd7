// SPDX-License-Identifier: Apache-2.0
#pragma once
// The settle CLI's options, declared once. Every option of every command is one OptionSpec row
// (name, unit, default, valid range, help); commands that share options share the rows (the
// move, plant, drive and bus groups). Parsing (the table's own tokeniser; CLI11 only lays out
// --help), validation (number, integer, range, list, choice, duplicates, unknown options with the
// nearest valid one) and the help text all come from these rows, so an option is checked in one
// place and its help cannot drift from it.
//
// Errors keep one form: exit 2 and one line "settle: error: <message> [<code>]" on stderr, or
// with --json the object {"status":"error","error":code,"parameter":option,"message":...} on
// stdout.
#include <cstddef>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "settle/plant/move_vocabulary.hpp"

#include "settle/plant/limits.hpp"

namespace settle::app {

// A closed or open interval of valid values (the move's own ranges are plant::move_range).
using Range = plant::Range;

enum class Kind : unsigned char {
  real,     // a finite number in `range`
  integer,  // a whole number (decimal digits, no exponent) in `range`
  text,     // any non-empty string (a path, an interface name)
  choice,   // one of `choices`
  list,     // comma-separated numbers, `min_items`..`max_items` of them, each in `range`
  flag,     // no value
};

struct OptionSpec {
  std::string name;  // "--time"
  Kind kind;
  std::string unit;  // "s", "rad/s", "" when dimensionless
  std::string def;   // default as shown in help; "" = required or absent
  std::string help;
  Range range{0.0, 0.0};
  std::vector<std::string> choices{};
  std::size_t min_items{1};
  std::size_t max_items{1};
  bool repeatable{false};             // may be given more than once (--mode)
  std::size_t max_repeats{1};         // when repeatable
  std::vector<Range> item_ranges{};   // list: one range per position (overrides `range`)
  std::string value_name{};           // placeholder in help (defaults by kind)
  bool hex{false};                    // integer: 0x-prefixed hexadecimal is accepted too
  bool per_axis{false};               // real: also a comma list, one value per axis (--axes N)
  // The default under `--timing drive` when it differs from `def` (the default under `--timing
  // sim`, the preset in force unless another is given): a drive on a real-time bus, not the
  // simulated drive on a loaded host. Shown in help next to `def`.
  std::string timing_drive{};
  // The move's design parameter this option gives (--time, --zeta, ...): a move whose profile and
  // shaper do not use it (core's registry) refuses it (move_options.cpp).
  std::optional<core::Param> param{};

  // One line for help: "<help> [unit; default; range]".
  [[nodiscard]] std::string describe() const;
};

using OptionGroup = std::span<const OptionSpec>;

struct CommandSpec {
  std::string name;
  std::string summary;
  std::string usage;                 // extra positional part, e.g. "000|001|004"
  std::vector<OptionGroup> groups;   // in help order
  std::vector<std::string> positional_choices{};  // reproduce's experiment, drive nmt's command
  std::string positional_name{"experiment"};      // what the positional is called in help and errors
  std::string notes{};               // bounds and remarks printed after the options
  std::string example{};             // one command line a user can type (help's "Example:")
};

// --help's layout: no line wider than this many columns.
inline constexpr std::size_t kHelpColumns = 100;

// The move group's rows (plan, sample, simulate, stream): the ones with a `param` are the design
// parameters checked against the profile's and shaper's use of them.
[[nodiscard]] OptionGroup move_options();

// Every command, in the order `settle --help` lists them.
[[nodiscard]] std::span<const CommandSpec> commands();
[[nodiscard]] const CommandSpec* find_command(std::string_view name);
// Every option a command accepts (flattened groups, including --json and --help).
[[nodiscard]] std::vector<const OptionSpec*> options_of(const CommandSpec& c);

struct RequestError {
  std::string code;     // a core/sim status code or a CLI code such as "bad_number"
  std::string param;    // the offending option, e.g. "--time"
  std::string message;  // one sentence
};

// The validated values of one command line.
class ParsedArgs {
 public:
  [[nodiscard]] bool has(const std::string& name) const { return raw_.count(name) != 0; }
  [[nodiscard]] bool flag(const std::string& name) const { return has(name); }
  [[nodiscard]] double real(const std::string& name, double fallback) const;
  [[nodiscard]] std::optional<double> real(const std::string& name) const;
  [[nodiscard]] std::vector<double> reals(const std::string& name) const;  // every value (repeatable)
  [[nodiscard]] long long integer(const std::string& name, long long fallback) const;
  // The value given, else the option table's default (under the --timing preset in force): the
  // table states each default once and call sites repeat none. Throws std::logic_error when the
  // option has neither (no numeric default in the table: a programming error).
  [[nodiscard]] long long integer(const std::string& name) const;
  [[nodiscard]] double real_or_default(const std::string& name) const;
  [[nodiscard]] std::string text_or_default(const std::string& name) const;
  [[nodiscard]] std::string text(const std::string& name, const std::string& fallback) const;
  [[nodiscard]] std::optional<std::string> text(const std::string& name) const;
  [[nodiscard]] std::vector<double> list(const std::string& name) const;                // first value
  [[nodiscard]] std::vector<std::vector<double>> lists(const std::string& name) const;  // every value
  // (a per-axis real option's values are lists too: a single number is a list of one)
  [[nodiscard]] const std::string& positional() const { return positional_; }
  [[nodiscard]] bool json() const { return json_; }

 private:
  friend struct Parser;
  std::map<std::string, std::vector<std::string>> raw_;
  std::map<std::string, std::vector<double>> numbers_;
  std::map<std::string, std::vector<std::vector<double>>> lists_;
  std::map<std::string, std::string> defaults_;  // the table's default of each option not given
  std::string positional_;
  bool json_{false};
};

enum class ParseOutcome : unsigned char { ok, help_printed, error };

// Parses and validates argv (the arguments after the command name) against the command's
// options. On error fills `err`; with --help prints the help on stdout.
[[nodiscard]] ParseOutcome parse_command(const CommandSpec& c, int argc, char** argv, ParsedArgs& out,
                                         RequestError& err);

// The help of one command, and of the whole program.
[[nodiscard]] std::string command_help(const CommandSpec& c);
[[nodiscard]] std::string program_help();

// The valid option nearest to `given` (edit distance), or "" when none is close.
[[nodiscard]] std::string nearest_option(const CommandSpec& c, std::string_view given);

// Strict number parsing: the whole string, no spaces; false otherwise. nan/inf parse (so that
// the caller can say "not finite" rather than "not a number").
[[nodiscard]] bool parse_real(const std::string& s, double& out);
[[nodiscard]] bool parse_integer(const std::string& s, long long& out);

// Checks one value as the parser checks option `o`'s (kind, number, range), for a value whose
// valid range depends on another option (settle drive write --value on --type). The number, when
// the kind has one, goes to `number`.
[[nodiscard]] bool check_value(const OptionSpec& o, const std::string& value, double& number, RequestError& err);

// A command's start: parses its options. Returns -1 to go on, or the exit status to return (0
// after --help, 2 after a bad request has been reported).
[[nodiscard]] int parse_or_exit(std::string_view command, int argc, char** argv, ParsedArgs& out);

// A number as %g prints it ("1e+06"), for messages.
[[nodiscard]] std::string format_number(double v);

// Prints the error (stderr line, or JSON on stdout when json is set) and returns exit status 2.
int report_bad_request(const RequestError& err, bool json);
// A runtime failure (a bus that cannot be opened, a file that cannot be written, a run that could
// not be made), in the one form every command uses: "settle <command>: <message> [<code>]" on
// stderr, or with --json the object {"status":"error","error":code,"message":...} on stdout (as a
// bad request's, without "parameter"). Returns exit status 1.
int report_failure(std::string_view command, const std::string& code, const std::string& message, bool json);

// The CLI's documented size bounds, checked before anything is allocated or printed. Each keeps
// a valid run of a release build within a few seconds (and under ASan within about a minute).
inline constexpr double kMaxRows = plant::kMaxSampleCount;  // sample: samples printed
inline constexpr double kMaxSimWork = plant::kMaxSimWork;  // simulate: grid steps x modes
inline constexpr double kMaxCsvRows = 1e6;       // simulate --csv: rows (the history is kept in memory)
inline constexpr double kMaxSeconds = plant::kMaxMoveSeconds;    // a move, move + tail, move + settle time
inline constexpr double kMaxStreamPeriods = 1e6; // stream: start-up (5 s) + move + settle, in periods
inline constexpr std::size_t kMaxModes = 64;     // --mode

// Every setpoint and every load position must fit the drive's 32-bit counts: a move whose largest
// |position| is `reach` (m or rad) fits when (2 reach + 1) x counts per unit stays within 2e9 for
// the motor's and the load's scale. Returns the option of the scale it does not fit
// ("--counts-per-unit" first, then "--load-counts-per-unit"), or nullptr when it fits both.
[[nodiscard]] const char* counts_reach_exceeded(double reach, double counts_per_unit, double load_counts_per_unit);

}  // namespace settle::app
