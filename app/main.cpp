// SPDX-License-Identifier: Apache-2.0
// settle: the command-line front end. Commands and their options are declared in options.cpp;
// each cmd_*.cpp turns validated options into a library call and prints the result.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>

#include "commands.hpp"
#include "options.hpp"

namespace {

struct Entry {
  const char* name;
  int (*run)(int, char**);
};

constexpr Entry kRun[] = {
    {"plan", settle::app::cmd_plan},         {"sample", settle::app::cmd_sample},
    {"simulate", settle::app::cmd_simulate}, {"reproduce", settle::app::cmd_reproduce},
    {"plant", settle::app::cmd_plant},       {"stream", settle::app::cmd_stream},
    {"demo", settle::app::cmd_demo},         {"drive", settle::app::cmd_drive},
    {"tune", settle::app::cmd_tune},
    {"export", settle::app::cmd_export},
    {"identify", settle::app::cmd_identify},
};

int unknown_command(const char* name) {
  std::fprintf(stderr, "settle: error: unknown command '%s' (plan, sample, simulate, reproduce, plant, stream, tune, demo, drive, identify) [bad_command]\n",
               name);
  return settle::app::kExitBadRequest;
}

// Every command's output ends here: a write that failed (a full disk, a closed pipe, /dev/full) is
// a runtime failure, never exit 0 with the output lost.
int finish(int status) {
  if (std::fflush(stdout) != 0 || std::ferror(stdout) != 0) {
    std::fprintf(stderr, "settle: error: cannot write standard output: %s [write_failed]\n", std::strerror(errno));
    return settle::app::kExitFailure;
  }
  return status;
}

int run(int argc, char** argv) {
  using namespace settle::app;
  if (argc < 2) {
    std::fputs(program_help().c_str(), stderr);
    return kExitBadRequest;
  }
  const std::string_view first = argv[1];
  if (first == "--version") {
    std::printf("settle %s\n", SETTLE_VERSION);
    return kExitOk;
  }
  if (first == "--help" || first == "-h") {
    std::fputs(program_help().c_str(), stdout);
    return kExitOk;
  }
  if (first == "help") {  // settle help [<command> [<subcommand>]]
    if (argc < 3) {
      std::fputs(program_help().c_str(), stdout);
      return kExitOk;
    }
    const bool drive = std::string_view{argv[2]} == "drive";
    if (argc > (drive ? 4 : 3)) {
      std::fprintf(stderr, "settle: error: usage: settle help [<command>] [bad_command]\n");
      return kExitBadRequest;
    }
    if (drive && argc == 3) {
      char help[] = "--help";
      char* args[] = {help, nullptr};
      return cmd_drive(1, args);
    }
    const std::string name = argc == 4 ? std::string{argv[2]} + " " + argv[3] : std::string{argv[2]};
    const CommandSpec* c = find_command(name);
    if (c == nullptr) return unknown_command(name.c_str());
    std::fputs(command_help(*c).c_str(), stdout);
    return kExitOk;
  }
  for (const Entry& e : kRun) {
    if (first == e.name) return e.run(argc - 2, argv + 2);
  }
  return unknown_command(argv[1]);
}
}  // namespace

int main(int argc, char** argv) { return finish(run(argc, argv)); }
