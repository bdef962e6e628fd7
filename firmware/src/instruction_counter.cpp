// SPDX-License-Identifier: Apache-2.0
// SysTick as an instruction clock. Under `-icount shift=N` QEMU advances its virtual clock by
// exactly 2^N ns per guest instruction and makes device reads exact at instruction granularity,
// so SysTick (on the core clock) advances 2^N * f_core / 1e9 counts per instruction.
#include "settle/firmware/instruction_counter.hpp"

#include <cstddef>

namespace settle::firmware {
namespace {

struct SysTick {
  std::uint32_t control;  // SYST_CSR
  std::uint32_t reload;   // SYST_RVR
  std::uint32_t current;  // SYST_CVR
};

constexpr std::uintptr_t systick_address{0xE000E010};
constexpr std::uint32_t systick_enable{1U << 0};
constexpr std::uint32_t systick_core_clock{1U << 2};
constexpr std::uint32_t systick_mask{0x00FF'FFFF};

volatile SysTick& systick() { return *reinterpret_cast<volatile SysTick*>(systick_address); }

// SysTick counts down, modulo 2^24.
std::uint32_t elapsed(std::uint32_t start, std::uint32_t end) {
  return (start - end) & systick_mask;
}

// Runs exactly 2 * iterations instructions (SUBS + BNE per iteration). GCC hands ARMv6-M inline
// assembly to the assembler in divided syntax, where SUBS has no immediate form; hence the switch.
[[gnu::noinline]] void known_loop(std::uint32_t iterations) {
  asm volatile(
      ".syntax unified\n"
      "1:\n"
      "subs %[n], %[n], #1\n"
      "bne 1b\n"
      : [n] "+l"(iterations)
      :
      : "cc");
}

std::uint32_t ticks_of_known_loop(std::uint32_t iterations) {
  const std::uint32_t start{InstructionCounter::now()};
  known_loop(iterations);
  return elapsed(start, InstructionCounter::now());
}

void empty_body() { asm volatile(""); }

// Both the body and the empty baseline are timed by this same code, so its cost cancels.
// The pointer goes through a volatile so the call cannot be inlined or specialised.
[[gnu::noinline]] std::uint32_t ticks_of_call(void (*body)()) {
  void (*volatile const call)(){body};
  const std::uint32_t start{InstructionCounter::now()};
  call();
  return elapsed(start, InstructionCounter::now());
}

}  // namespace

InstructionCounter InstructionCounter::calibrate() {
  systick().control = 0;
  systick().reload = systick_mask;
  systick().current = 0;  // clears the count; SysTick reloads on its next clock
  systick().control = systick_enable | systick_core_clock;
  // No interrupt: windows are short and elapsed() works modulo 2^24.

  // Two lengths, so what surrounds the loop cancels. 3.2 M instructions is under 2^24 counts on
  // both boards at shift 7 and long enough that one count of quantisation is < 1e-6.
  constexpr std::uint32_t short_loop{100'000};
  constexpr std::uint32_t long_loop{1'700'000};
  const std::uint32_t short_ticks{ticks_of_known_loop(short_loop)};
  const std::uint32_t long_ticks{ticks_of_known_loop(long_loop)};
  InstructionCounter counter{2U * (long_loop - short_loop), long_ticks - short_ticks};

  // The cheapest of a few back-to-back reads is the cost of a read itself.
  std::uint32_t overhead{systick_mask};
  for (int i{0}; i < 8; ++i) {
    const std::uint32_t start{now()};
    const std::uint32_t ticks{elapsed(start, now())};
    overhead = ticks < overhead ? ticks : overhead;
  }
  counter.read_overhead_ticks_ = overhead;
  return counter;
}

std::uint32_t InstructionCounter::now() { return systick().current & systick_mask; }

std::uint32_t InstructionCounter::rounded_instructions(std::uint32_t ticks) const {
  if (calibration_ticks_ == 0U) {
    return 0;  // SysTick did not run: not under QEMU, or a machine without a core clock
  }
  return static_cast<std::uint32_t>(
      (std::uint64_t{ticks} * calibration_instructions_ + calibration_ticks_ / 2U) /
      calibration_ticks_);
}

std::uint32_t InstructionCounter::instructions(std::uint32_t start, std::uint32_t end) const {
  const std::uint32_t total{rounded_instructions(elapsed(start, end))};
  const std::uint32_t reads{rounded_instructions(read_overhead_ticks_)};
  return total > reads ? total - reads : 0U;
}

std::uint32_t InstructionCounter::milli_instructions_per_tick() const {
  if (calibration_ticks_ == 0U) {
    return 0;
  }
  return static_cast<std::uint32_t>(std::uint64_t{calibration_instructions_} * 1000U /
                                    calibration_ticks_);
}

InstructionCost InstructionCounter::measure(void (*body)(), std::uint32_t calls) const {
  if (calls == 0U || calibration_ticks_ == 0U) {
    return {};
  }
  // The empty call is deterministic; its cheapest sample is its cost.
  std::uint32_t baseline_ticks{systick_mask};
  std::uint64_t baseline_sum{0};
  constexpr std::uint32_t baseline_calls{64};
  for (std::uint32_t i{0}; i < baseline_calls; ++i) {
    const std::uint32_t ticks{ticks_of_call(empty_body)};
    baseline_ticks = ticks < baseline_ticks ? ticks : baseline_ticks;
    baseline_sum += ticks;
  }
  const std::uint32_t baseline{rounded_instructions(baseline_ticks)};

  InstructionCost cost{
      .min = UINT32_MAX, .max = 0, .calls = calls, .bracket = baseline, .exact = exact()};
  std::uint64_t tick_sum{0};
  std::uint64_t instruction_sum{0};
  for (std::uint32_t i{0}; i < calls; ++i) {
    const std::uint32_t ticks{ticks_of_call(body)};
    tick_sum += ticks;
    const std::uint32_t total{rounded_instructions(ticks)};
    const std::uint32_t own{total > baseline ? total - baseline : 0U};
    instruction_sum += own;
    cost.min = own < cost.min ? own : cost.min;
    cost.max = own > cost.max ? own : cost.max;
  }
  if (cost.exact) {
    cost.mean_centi = static_cast<std::int64_t>(instruction_sum * 100U / calls);
    return cost;
  }
  // Single calls not resolved: the mean from the raw counts is then the amortised cost.
  const auto per_call_ticks_centi{
      static_cast<std::int64_t>(tick_sum * 100U / calls) -
      static_cast<std::int64_t>(baseline_sum * 100U / baseline_calls)};
  cost.mean_centi = per_call_ticks_centi * std::int64_t{calibration_instructions_} /
                    std::int64_t{calibration_ticks_};
  return cost;
}

}  // namespace settle::firmware
