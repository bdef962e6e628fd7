// SPDX-License-Identifier: Apache-2.0
// Streams a tuned plan on a Cortex-M4F without the planner: the headers `settle export` wrote from
// the plan file hold the move as constant tables (in double, float and fixed point), and
// settle/core/exported_plan.hpp turns each into one target in counts per tick, as a servo loop
// would send them. Prints "tick double float fixed" per line on the semihosting console, then
// "exported_plan: <ticks> ticks, at <target> counts" (tools compare it with `settle sample`).
#include <cstdint>

#include "plan_double.hpp"
#include "plan_fixed.hpp"
#include "plan_float.hpp"
#include "settle/firmware/runtime.hpp"
#include "settle/firmware/semihosting.hpp"
#include "settle/firmware/text.hpp"

namespace fw = settle::firmware;

int settle::firmware::image_main() {
  plan_double::Stream d{plan_double::kPlan, 0};
  plan_float::Stream f{plan_float::kPlan, 0};
  plan_fixed::Stream x{plan_fixed::kPlan, 0};
  std::int32_t tick = 0, target = 0;
  for (bool last = false; !last; ++tick) {
    bool last_d = false, last_f = false, last_x = false;
    const std::int32_t pd = d.next(last_d), pf = f.next(last_f), px = x.next(last_x);
    if (last_d != last_f || last_d != last_x) {
      (void)fw::semihosting::write_console("exported_plan: the streams end on different ticks\n");
      return 1;
    }
    last = last_d;
    target = pd;
    fw::Text<64> line{};
    line.append_signed(tick).append(" ").append_signed(pd).append(" ").append_signed(pf).append(" ").append_signed(px).append("\n");
    if (!fw::semihosting::write_console(line.view())) return 1;
  }
  fw::Text<96> done{};
  done.append("exported_plan: ").append_signed(tick).append(" ticks, at ").append_signed(target).append(" counts\n");
  (void)fw::semihosting::write_console(done.view());
  return 0;
}
