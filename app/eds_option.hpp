// SPDX-License-Identifier: Apache-2.0
// --eds FILE (and --strict): the drive's description, read once and the same way by every
// command that takes one (drive info|read|write|scan|config, stream, plant, identify), before
// anything is sent. Refused (exit 2, error bad_eds, the message naming the section, the key and
// the rule) when the reader refuses the file or what it says cannot be for the node(s) in use
// (hal/eds_semantics.hpp); each deviation the reader tolerated is printed on stderr as a warning,
// and --strict refuses the file at the first one instead.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "options.hpp"
#include "settle/hal/eds_reader.hpp"
#include "settle/testbed/stream.hpp"

namespace settle::app {

struct EdsOption {
  std::shared_ptr<const hal::eds::Description> description;  // null: no --eds given
  std::vector<hal::eds::Problem> warnings;                    // the reader's, then the nodes'
};

// Exit status (2) or -1. `command` names the command in the warnings ("drive info").
[[nodiscard]] int load_eds_option(const ParsedArgs& args, const std::string& command,
                                  std::span<const std::uint8_t> nodes, EdsOption& out);

// --load-feedback INDEX:SUB (stream, identify): INDEX 0x1000..0xFFFF and SUB 0..255, decimal or 0x
// hex; it needs --eds, whose description must have the object as a readable, PDO-mappable
// INTEGER32. Exit status (2, naming --load-feedback) or -1 with `out` set (index 0 when not given).
[[nodiscard]] int parse_load_feedback(const ParsedArgs& args, const hal::eds::Description* eds,
                                      testbed::LoadFeedback& out);

}  // namespace settle::app
