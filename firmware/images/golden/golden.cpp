// SPDX-License-Identifier: Apache-2.0
// golden-<board>: core::fixed::golden_checksum() on the target (every fixed-point build, position
// plan and tick of a fixed list of moves, folded into four 64-bit checksums), written to golden-<board>.txt
// as one line. tests/cross/golden-check compares it with the same line from the host
// (`settle_servo_image_host --golden`): equal means the ARM image computes every fixed-point
// setpoint bit for bit as x86-64 does. Planning runs on the target too (the list is planned, not
// pinned), which needs ~1.5 KiB of stack besides plan()'s own.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "settle/core/fixed/golden.hpp"
#include "settle/firmware/runtime.hpp"
#include "settle/firmware/semihosting.hpp"
#include "settle/firmware/text.hpp"

namespace {
template <std::size_t N>
void append_checksum(settle::firmware::Text<N>& t, std::string_view key, std::uint64_t v) {
  t.append(key).append(" ").append_hex(static_cast<std::uint32_t>(v >> 32U), 8);
  t.append_hex(static_cast<std::uint32_t>(v), 8).append(" ");
}
}  // namespace

int settle::firmware::image_main() {
  const core::fixed::GoldenResult g = core::fixed::golden_checksum();
  Text<256> rep{};
  append_checksum(rep, "build", g.build);
  append_checksum(rep, "ticks", g.ticks);
  append_checksum(rep, "plan", g.plan);
  append_checksum(rep, "positions", g.positions);
  rep.append("moves ").append_unsigned(g.moves).append(" samples ").append_unsigned(g.samples);
  rep.append(" position_samples ").append_unsigned(g.position_samples);
  rep.append(" status ").append(core::to_string(g.status)).append("\n");
  Text<40> name{};
  name.append("golden-").append(SETTLE_BOARD_NAME).append(".txt");
  semihosting::File file{semihosting::File::open(name.view(), semihosting::OpenMode::write)};
  if (!(file.write(rep.view()) && file.close()) || rep.overflowed()) return 2;
  static_cast<void>(semihosting::write_console(rep.view()));
  rep.clear();
  rep.append("stack_high_water ").append_unsigned(stack_high_water()).append(" of ").append_unsigned(stack_size());
  rep.append("\n");
  static_cast<void>(semihosting::write_console(rep.view()));
  return g.status == core::Status::ok ? 0 : 1;
}
