// SPDX-License-Identifier: Apache-2.0
// Every status enum of runtime and hal is made from one list: for each enumerator, to_string gives
// its code (or, for the enums whose to_string is a sentence, that sentence) and describe a sentence
// of its own; a value past the list gives the fallback, never a neighbour's text.
#include <gtest/gtest.h>

#include <cstddef>
#include <set>
#include <string>

#include "settle/hal/canopen/cia402.hpp"
#include "settle/hal/canopen/process_data.hpp"
#include "settle/hal/canopen/remote_drive.hpp"
#include "settle/runtime/servo_loop.hpp"
#include "settle/runtime/session.hpp"

using namespace settle;
namespace co = settle::hal::canopen;

namespace {

#define COUNT_ONE(name, text) +1
template <typename E> E nth(std::size_t i) { return static_cast<E>(i); }

// n enumerators: n distinct non-empty names from `name`, and `fallback` for value n.
template <typename E, typename F>
void expect_names(std::size_t n, F name, const std::string& fallback) {
  std::set<std::string> seen;
  for (std::size_t i = 0; i < n; ++i) {
    const std::string s = name(nth<E>(i));
    EXPECT_FALSE(s.empty()) << i;
    EXPECT_NE(s, fallback) << i;
    EXPECT_TRUE(seen.insert(s).second) << "two enumerators share '" << s << "'";
  }
  EXPECT_EQ(name(nth<E>(n)), fallback);
  EXPECT_EQ(name(nth<E>(0xFF)), fallback);
}

template <typename E> void expect_codes_and_sentences(std::size_t n, const std::string& fallback) {
  expect_names<E>(n, [](E e) { return std::string{to_string(e)}; }, fallback);
  expect_names<E>(n, [](E e) { return std::string{describe(e)}; }, fallback);
}

}  // namespace

TEST(StatusNames, RuntimeCodesAndSentencesComeFromOneListEach) {
  using namespace settle::runtime;
  expect_codes_and_sentences<LoopStatus>(0 SETTLE_LOOP_STATUSES(COUNT_ONE), "unknown");
  expect_codes_and_sentences<AxisFault>(0 SETTLE_AXIS_FAULTS(COUNT_ONE), "unknown");
  expect_codes_and_sentences<LoopEventKind>(0 SETTLE_LOOP_EVENT_KINDS(COUNT_ONE), "unknown");
  expect_codes_and_sentences<SessionOutcome>(0 SETTLE_SESSION_OUTCOMES(COUNT_ONE), "unknown");
  // The codes are the enumerators' names (logs and JSON use them), in the enum's order.
  EXPECT_STREQ(to_string(LoopStatus::evaluation_refused), "evaluation_refused");
  EXPECT_STREQ(to_string(LoopStatus::bad_axis_config), "bad_axis_config");
  EXPECT_STREQ(to_string(AxisFault::send_failed), "send_failed");
  EXPECT_STREQ(to_string(LoopEventKind::bus_restart_refused), "bus_restart_refused");
  EXPECT_STREQ(to_string(SessionOutcome::step_guard), "step_guard");
  EXPECT_STREQ(describe(SessionOutcome::timeout), "the session ran past max_ticks");
}

TEST(StatusNames, HalCodesAndSentencesComeFromOneListEach) {
  expect_codes_and_sentences<co::RemoteDriveState>(0 SETTLE_HAL_REMOTE_DRIVE_STATES(COUNT_ONE), "?");
  expect_codes_and_sentences<co::StartupError>(0 SETTLE_HAL_STARTUP_ERRORS(COUNT_ONE), "?");
  expect_codes_and_sentences<co::LayoutError>(0 SETTLE_HAL_LAYOUT_ERRORS(COUNT_ONE), "?");
  expect_names<co::Cia402State>(
      0 SETTLE_HAL_CIA402_STATES(COUNT_ONE), [](co::Cia402State s) { return std::string{to_string(s)}; }, "?");
  EXPECT_STREQ(to_string(co::RemoteDriveState::not_operational), "not_operational");
  EXPECT_STREQ(to_string(co::StartupError::mapping_unsuitable), "mapping_unsuitable");
  EXPECT_STREQ(to_string(co::LayoutError::gap), "gap");
  EXPECT_STREQ(to_string(co::Cia402State::quick_stop_active), "quick stop active");
}
