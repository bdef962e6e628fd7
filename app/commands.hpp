// SPDX-License-Identifier: Apache-2.0
#pragma once
// The settle subcommands. Each takes the arguments after its own name and returns the process
// exit status: 0 success (finite output only), 2 bad request (a one-line error on stderr naming
// the option, or JSON with --json), 1 a runtime failure (a bus that cannot be opened, a move
// that did not complete, a file that cannot be written).
namespace settle::app {

int cmd_plan(int argc, char** argv);
int cmd_sample(int argc, char** argv);
int cmd_simulate(int argc, char** argv);
int cmd_reproduce(int argc, char** argv);
int cmd_plant(int argc, char** argv);
int cmd_stream(int argc, char** argv);
int cmd_identify(int argc, char** argv);
int cmd_demo(int argc, char** argv);
int cmd_tune(int argc, char** argv);
int cmd_export(int argc, char** argv);
// settle drive info|read|write|scan: argv[0] is the subcommand.
int cmd_drive(int argc, char** argv);

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitBadRequest = 2;

}  // namespace settle::app
