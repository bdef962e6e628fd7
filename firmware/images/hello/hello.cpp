// SPDX-License-Identifier: Apache-2.0
// The smallest image worth running on a board: proves startup, semihosting file output and the
// exit status end to end, and is the harness of the instruction-count method: it checks the
// counter on a body of known length, then measures one single-precision sine.
#include <cmath>
#include <cstdint>

#include "settle/firmware/instruction_counter.hpp"
#include "settle/firmware/runtime.hpp"
#include "settle/firmware/semihosting.hpp"
#include "settle/firmware/text.hpp"

namespace {

using settle::firmware::InstructionCost;
using settle::firmware::InstructionCounter;
using settle::firmware::Text;
namespace semihosting = settle::firmware::semihosting;

constexpr std::string_view board{SETTLE_BOARD_NAME};

// Exactly ten instructions besides its return: the counter must report 10.00 for it.
[[gnu::noinline]] void ten_instructions() {
  asm volatile("nop\n nop\n nop\n nop\n nop\n nop\n nop\n nop\n nop\n nop\n");
}

// Volatile, so the sine is evaluated each call on an input the compiler cannot predict.
volatile float sine_input{0.25F};
volatile float sine_output{};

[[gnu::noinline]] void sine_once() {
  const float x{sine_input};
  sine_output = std::sin(x);
  sine_input = x + 0.001F;
}

template <std::size_t N>
void append_cost(Text<N>& text, std::string_view name, const InstructionCost& cost) {
  text.append(name)
      .append(": mean ")
      .append_scaled(cost.mean_centi, 2)
      .append(" min ")
      .append_unsigned(cost.min)
      .append(" max ")
      .append_unsigned(cost.max)
      .append(" instructions per call over ")
      .append_unsigned(cost.calls)
      .append(" calls (timing bracket ")
      .append_unsigned(cost.bracket)
      .append(cost.exact ? " subtracted)\n" : " subtracted; not exact: -icount shift too small)\n");
}

}  // namespace

int settle::firmware::image_main() {
  const InstructionCounter counter{InstructionCounter::calibrate()};
  const InstructionCost known{counter.measure(ten_instructions, 100)};
  const InstructionCost sine{counter.measure(sine_once, 1000)};

  Text<512> report{};
  report.append("settle hello from ").append(board).append("\n");
  report.append("instructions per SysTick count: ")
      .append_scaled(static_cast<std::int64_t>(counter.milli_instructions_per_tick()), 3)
      .append("\n");
  append_cost(report, "known 10-instruction body", known);
  append_cost(report, "sinf", sine);
  report.append("stack high water: ")
      .append_unsigned(stack_high_water())
      .append(" of ")
      .append_unsigned(stack_size())
      .append(" bytes\n");

  Text<32> name{};
  name.append("hello-").append(board).append(".txt");
  semihosting::File file{semihosting::File::open(name.view(), semihosting::OpenMode::write)};
  const bool written{file.write(report.view()) && file.close()};
  static_cast<void>(semihosting::write_console(report.view()));

  if (!written || report.overflowed()) {
    fatal("hello: could not write the report file\n", 2);
  }
  // Without -icount the counter measures host time, not instructions; refuse to look valid.
  if (!known.exact || known.min != 10 || known.max != 10) {
    fatal("hello: the instruction counter is off (is QEMU running with -icount shift=7?)\n", 3);
  }
  return 0;
}
