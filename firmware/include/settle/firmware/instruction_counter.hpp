// SPDX-License-Identifier: Apache-2.0
#pragma once
// Counts the instructions code costs on QEMU's emulated Cortex-M cores: the per-tick cost
// measure of the firmware images. Needs QEMU's `-icount shift=7` (128 virtual ns per instruction),
// under which SysTick resolves single instructions; the method is in firmware/README.md.

#include <cstdint>

namespace settle::firmware {

// One measurement of a function over many calls.
struct InstructionCost {
  std::int64_t mean_centi{};  // mean instructions per call, in hundredths
  std::uint32_t min{};        // fewest instructions one call took (exact runs only)
  std::uint32_t max{};        // most instructions one call took (exact runs only)
  std::uint32_t calls{};
  // What the timing bracket itself costs (two SysTick reads, the indirect call and the empty
  // function's return); already subtracted from the figures above.
  std::uint32_t bracket{};
  // Whether the clock resolved single instructions (QEMU ran with a large enough -icount shift);
  // otherwise min and max are meaningless and the mean is an estimate.
  bool exact{};
};

class InstructionCounter {
 public:
  // Starts SysTick free-running on the core clock and measures, with a loop of known length,
  // how many instructions one SysTick count is worth and what reading the clock costs.
  [[nodiscard]] static InstructionCounter calibrate();

  // The raw 24-bit SysTick count (it counts down). One window between two reads must stay
  // shorter than 2^24 counts: 5.2 M instructions on mps2-an386, 8.2 M on the micro:bit.
  [[nodiscard]] static std::uint32_t now();

  // Instructions executed between two now() reads, the cost of the reads themselves removed.
  [[nodiscard]] std::uint32_t instructions(std::uint32_t start, std::uint32_t end) const;

  // Calls `body` `calls` times through a function pointer, timing each call, and subtracts the
  // same timed call of an empty function: what remains is what the body adds, i.e. its
  // instructions, return included, less the empty function's single return (BX LR).
  [[nodiscard]] InstructionCost measure(void (*body)(), std::uint32_t calls) const;

  // Instructions per SysTick count, in thousandths (312 on mps2-an386 at shift 7: 128 ns per
  // instruction against a 25 MHz SysTick).
  [[nodiscard]] std::uint32_t milli_instructions_per_tick() const;

  // True when one SysTick count is worth less than half an instruction, so that rounding
  // recovers every instruction count exactly.
  [[nodiscard]] bool exact() const { return 2U * calibration_instructions_ < calibration_ticks_; }

 private:
  InstructionCounter(std::uint32_t instructions, std::uint32_t ticks)
      : calibration_instructions_{instructions}, calibration_ticks_{ticks} {}
  [[nodiscard]] std::uint32_t rounded_instructions(std::uint32_t ticks) const;

  std::uint32_t calibration_instructions_;
  std::uint32_t calibration_ticks_;
  std::uint32_t read_overhead_ticks_{};
};

}  // namespace settle::firmware
