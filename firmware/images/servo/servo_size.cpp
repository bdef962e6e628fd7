// SPDX-License-Identifier: Apache-2.0
// What one axis of the servo loop costs in flash and RAM, without the test harness around it:
// ServoLoop<float, 1 axis> with the pinned move queued, ticking on a CAN controller's buffers
// (hal::MailboxBus: three transmit mailboxes, an 8-frame receive FIFO), whose sent frames leave
// for a bus where nobody answers (no drive, no loopback, no log). Nothing is streamed; the image
// exists for arm-none-eabi-size, and runs only to prove it links and starts.
#include <cstdint>

#include "servo_session.hpp"
#include "settle/hal/mailbox_bus.hpp"
#include "settle/firmware/runtime.hpp"
#include "settle/firmware/semihosting.hpp"
#include "settle/firmware/text.hpp"

namespace {

namespace fw = settle::firmware;
namespace rt = settle::runtime;
namespace hal = settle::hal;
namespace si = settle::firmware::servo_image;

si::Controller g_bus{};
si::Loop g_loop{g_bus, si::kScale.period_us};

}  // namespace

int settle::firmware::image_main() {
  rt::AxisConfig ac{};
  ac.drive.node = si::kNode;
  ac.scale = si::kScale;
  if (g_loop.add_axis(ac) != rt::LoopStatus::ok) return 1;
  g_loop.start(0);
  if (g_loop.submit(0, si::pinned_move()) != rt::LoopStatus::ok) return 1;
  hal::CanFrame wire{};
  for (std::uint64_t n = 1; n <= 100; ++n) {
    g_loop.tick(n * si::kScale.period_us);
    while (g_bus.take_sent(wire)) {
    }
  }
  // The stack this took: the Move<double> in this frame, then submitting converts it to the
  // loop's Move<float> in place (no temporaries); the tick's own worst path is smaller (stack-report).
  fw::Text<96> rep{};
  rep.append("stack_high_water ").append_unsigned(fw::stack_high_water()).append(" of ");
  rep.append_unsigned(fw::stack_size()).append("\n");
  fw::Text<40> name{};
  name.append("servo_size-").append(SETTLE_BOARD_NAME).append(".txt");
  fw::semihosting::File file{fw::semihosting::File::open(name.view(), fw::semihosting::OpenMode::write)};
  if (!(file.write(rep.view()) && file.close())) return 2;
  return g_bus.counters().sent > 0 ? 0 : 1;
}
