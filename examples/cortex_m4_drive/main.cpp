// SPDX-License-Identifier: Apache-2.0
// Drive master firmware for a Cortex-M4F: plan a move on the target, then stream it at 1 kHz with
// ServoLoop<float> (the FPU evaluates it) on the CAN controller's mailboxes, one tick per SysTick.
// The "wire" here is software: Settle's ideal CiA 402 drive (settle::hal_testing) in the same
// image, behind a second controller; on a board the controller's interrupts move the frames
// instead, and the drive is a real one.
#include <cstdint>

#include "settle/core/planner.hpp"
#include "settle/firmware/runtime.hpp"
#include "settle/firmware/semihosting.hpp"
#include "settle/runtime/session.hpp"
#include "settle/firmware/text.hpp"
#include "settle/hal/canopen/drive_node.hpp"
#include "settle/hal/mailbox_bus.hpp"
#include "settle/hal/testing/ideal_drive.hpp"

namespace {

namespace fw = settle::firmware;
namespace rt = settle::runtime;
namespace hal = settle::hal;

constexpr std::uint32_t kPeriodUs = 1000;
constexpr std::uint32_t kCoreHz = 25'000'000;  // mps2-an386's processor clock
volatile std::uint32_t systick_count = 0;

// SysTick paces the loop: wait() sleeps (WFI) until the next interrupt.
struct SysTickClock {
  std::uint32_t seen{0};
  void start() {
    auto reg = [](std::uintptr_t a) { return reinterpret_cast<volatile std::uint32_t*>(a); };
    *reg(0xE000E014) = kCoreHz / (1'000'000 / kPeriodUs) - 1;  // SYST_RVR
    *reg(0xE000E018) = 0;                                      // SYST_CVR
    *reg(0xE000E010) = 7;  // SYST_CSR: processor clock, interrupt, enable
  }
  std::uint64_t wait() {
    for (;;) {  // interrupts masked between the check and WFI (which a pending SysTick still wakes)
      asm volatile("cpsid i" ::: "memory");
      const bool ticked = systick_count != seen;
      if (!ticked) asm volatile("wfi" ::: "memory");
      asm volatile("cpsie i" ::: "memory");  // the handler runs here
      if (ticked) break;
    }
    const std::uint32_t now = systick_count;
    const std::uint32_t missed = now - seen - 1;
    seen = now;
    return missed;
  }
  [[nodiscard]] std::uint64_t now_us() const { return std::uint64_t{seen} * kPeriodUs; }
};

using Controller = hal::MailboxBus<3, 8>;  // 3 transmit mailboxes, 8-frame receive FIFO
using Loop = rt::ServoLoop<float, 1, 2, rt::FloatEvaluation<float>, Controller>;

// The drive: follows each setpoint exactly, one period after the SYNC that applies it, on its own
// controller (8 transmit mailboxes, a 16-frame receive FIFO).
using IdealDrive = hal::testing::IdealDrive<hal::MailboxBus<8, 16>>;

Controller controller;
Loop loop{controller, kPeriodUs};
IdealDrive drive{hal::canopen::DriveNodeConfig{.node = 1, .sync_period_us = kPeriodUs}};

void wire() {  // what the controllers' transmit and receive interrupts do on a board
  hal::CanFrame f{};
  while (controller.take_sent(f)) (void)drive.port().put_received(f);
  while (drive.port().take_sent(f)) (void)controller.put_received(f);
}

}  // namespace

extern "C" void settle_systick_handler() noexcept { systick_count = systick_count + 1; }

int settle::firmware::image_main() {
  settle::core::MoveRequest request{};
  request.distance = 0.05;  // m
  request.time = 0.3;       // s
  request.set_mode(22.0);     // rad/s: the mode the move leaves at rest
  settle::core::Move<double> move{};
  if (settle::core::plan(request, move) != settle::core::Status::ok) return 1;

  rt::AxisConfig axis{};
  axis.drive.node = 1;
  axis.scale = {1e6, kPeriodUs};  // 1 count = 1 µm, at the loop's period
  axis.vmax = 1.0;
  if (loop.add_axis(axis) != rt::LoopStatus::ok) return 1;
  drive.start(0);
  SysTickClock clock{};
  clock.start();
  rt::SessionConfig session{};
  session.settle_ticks = 200;
  const rt::SessionResult r = rt::run_session(loop, clock, &move, 1, session, [&](std::uint64_t, bool) {
    wire();
    drive.process(clock.now_us());
    wire();
    loop.feedback_log(0).clear();
  });

  fw::Text<128> line{};
  line.append("cortex_m4_drive: session ").append(rt::to_string(r.outcome)).append(" after ")
      .append_unsigned(r.ticks).append(" ticks; drive at ").append_signed(drive.position())
      .append(" counts (target ").append_signed(loop.record(0).target).append(")\n");
  (void)fw::semihosting::write_console(line.view());
  return r.outcome == rt::SessionOutcome::completed ? 0 : 1;
}
