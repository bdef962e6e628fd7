// SPDX-License-Identifier: Apache-2.0
// Built with RTTI against the installed CANopen components: typeid and dynamic_cast on the
// consumer's own types, one of them derived from hal's FrameSink and fed by hal's loopback bus and
// NMT encoder. Prints "rtti_consumer: ok" only when each check holds.
#include <cstdio>
#include <typeinfo>

#include "settle/hal/canopen/nmt.hpp"
#include "settle/hal/frame_sink.hpp"
#include "settle/hal/loopback_bus.hpp"
#include "settle/hal/socketcan_bus.hpp"
#include "settle/runtime/servo_loop.hpp"

namespace {

class CountingSink : public settle::hal::FrameSink {
 public:
  bool put(const settle::hal::CanFrame&) noexcept override {
    ++frames;
    return true;
  }
  int frames{0};
};

}  // namespace

int main() {
  settle::hal::LoopbackHub hub;
  settle::hal::LoopbackBus<8> a{hub}, b{hub};
  CountingSink sink;
  settle::hal::FrameSink* as_sink = &sink;
  if (!a.put(settle::hal::canopen::encode_nmt(settle::hal::canopen::NmtCommand::start, 1))) return 1;
  settle::hal::CanFrame frame{};
  while (b.receive(frame) == settle::hal::ReceiveStatus::received) (void)as_sink->put(frame);

  auto* back = dynamic_cast<CountingSink*>(as_sink);
  const bool same = typeid(*as_sink) == typeid(CountingSink);
  std::printf("rtti_consumer: typeid %s, dynamic_cast %s, %d frame(s)\n", same ? "matches" : "differs",
              back == &sink ? "found the sink" : "failed", sink.frames);
  // The servo loop and the SocketCAN bus are linked too (constructed, never run).
  static settle::hal::SocketCanBus can;
  static settle::runtime::ServoLoop<double> loop{can, 1000};
  (void)loop;
  if (!(same && back == &sink && sink.frames == 1)) return 1;
  std::puts("rtti_consumer: ok");
  return 0;
}
