// settle: the command-line front end. Commands and their options are declared in options.cpp;
// each cmd_*.cpp turns validated options into a library call and prints the result.
#include <cstdio>
#include <cstring>
#include <string_view>

#include "commands.hpp"
#include "options.hpp"

namespace {

struct Entry {
  const char* name;
  int (*run)(int, char**);
};

constexpr Entry kRun[] = {
    {"plan", settle::cli::cmd_plan},         {"sample", settle::cli::cmd_sample},
    {"simulate", settle::cli::cmd_simulate}, {"reproduce", settle::cli::cmd_reproduce},
    {"plant", settle::cli::cmd_plant},       {"stream", settle::cli::cmd_stream},
    {"demo", settle::cli::cmd_demo},
};

int unknown_command(const char* name) {
  std::fprintf(stderr, "settle: error: unknown command '%s' (plan, sample, simulate, reproduce, plant, stream, demo) [bad_command]\n",
               name);
  return settle::cli::kExitBadRequest;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace settle::cli;
  if (argc < 2) {
    std::fputs(program_help().c_str(), stderr);
    return kExitBadRequest;
  }
  const std::string_view first = argv[1];
  if (first == "--help" || first == "-h") {
    std::fputs(program_help().c_str(), stdout);
    return kExitOk;
  }
  if (first == "help") {  // settle help [<command>]
    if (argc < 3) {
      std::fputs(program_help().c_str(), stdout);
      return kExitOk;
    }
    if (argc > 3) {
      std::fprintf(stderr, "settle: error: usage: settle help [<command>] [bad_command]\n");
      return kExitBadRequest;
    }
    const CommandSpec* c = find_command(argv[2]);
    if (c == nullptr) return unknown_command(argv[2]);
    std::fputs(command_help(*c).c_str(), stdout);
    return kExitOk;
  }
  for (const Entry& e : kRun) {
    if (first == e.name) return e.run(argc - 2, argv + 2);
  }
  return unknown_command(argv[1]);
}
