#include <cstdio>
#include <cstring>

#include "commands.hpp"

namespace {

struct Command {
  const char* name;
  int (*run)(int, char**);
  const char* help;
};

constexpr Command kCommands[] = {
    {"plan", settle::cli::cmd_plan, "plan a move and print it (text or --json)"},
    {"sample", settle::cli::cmd_sample, "plan a move and print t,position,velocity,acceleration,jerk as CSV (--dt)"},
    {"plant", settle::cli::cmd_plant, "run the simulated CiA 402 drive with a plant behind it on a CAN bus"},
    {"stream", settle::cli::cmd_stream, "stream a move to a drive over CAN and measure the residual vibration"},
    // commands of the simulator issue
    {"simulate", settle::cli::cmd_simulate, "run a move on a plant (sdof, beam, belt, modes): residual, PRV, energy"},
    {"reproduce", settle::cli::cmd_reproduce, "rerun a paper's experiment (000, 001, 004) as tables, CSV and plots"},
};

void usage(std::FILE* f) {
  std::fprintf(f, "usage: settle <command> [options]\n\ncommands:\n");
  for (const Command& c : kCommands) std::fprintf(f, "  %-10s %s\n", c.name, c.help);
  std::fprintf(f, "\nrun 'settle <command> --help' for the options of a command\n");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0) {
    usage(argc < 2 ? stderr : stdout);
    return argc < 2 ? settle::cli::kExitBadRequest : settle::cli::kExitOk;
  }
  for (const Command& c : kCommands) {
    if (std::strcmp(argv[1], c.name) == 0) return c.run(argc - 2, argv + 2);
  }
  std::fprintf(stderr, "settle: unknown command '%s'\n", argv[1]);
  usage(stderr);
  return settle::cli::kExitBadRequest;
}
