// SPDX-License-Identifier: Apache-2.0
#pragma once
// Small builders shared by the core suites.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <cmath>
#include <optional>

#include "settle/core/planner.hpp"

namespace settle::test {

inline core::MoveRequest timed(core::ProfileKind k, double d, double t, double omega = 0.0, double zeta = 0.0) {
  core::MoveRequest r{};
  r.profile = k;
  r.distance = d;
  r.time = t;
  if (omega > 0.0) r.set_mode(omega, zeta);
  return r;
}

inline core::Move<double> must_plan(const core::MoveRequest& r) {
  core::Move<double> m{};
  const core::Status st = core::plan(r, m);
  if (st != core::Status::ok) ADD_FAILURE() << "plan failed: " << core::to_string(st);
  return m;
}

// The largest |v|, |a| and |j| of a planned move sampled at n + 1 evenly spread instants from 0
// to its end: an independent look at its peaks, not the planner's.
inline core::Peaks<double> sampled_peaks(const core::Move<double>& m, int n) {
  core::Peaks<double> pk{};
  for (int i = 0; i <= n; ++i) {
    const auto s = m.at(m.duration() * i / n);
    pk.v = std::max(pk.v, std::fabs(s.v));
    pk.a = std::max(pk.a, std::fabs(s.a));
    pk.j = std::max(pk.j, std::fabs(s.j));
  }
  return pk;
}

// m_neg is m mirrored: the same duration to the bit, and at n + 1 evenly spread instants its
// position, velocity, acceleration and jerk are m's negated exactly (a plan of -D against D).
inline void expect_mirrored(const core::Move<double>& m, const core::Move<double>& m_neg, int n = 2000) {
  EXPECT_EQ(std::bit_cast<std::uint64_t>(m_neg.duration()), std::bit_cast<std::uint64_t>(m.duration()))
      << m_neg.duration() << " s against " << m.duration() << " s";
  int off = 0;
  for (int i = 0; i <= n; ++i) {
    const double t = m.duration() * i / n;
    const auto s = m.at(t), sn = m_neg.at(t);
    off += !(sn.p == -s.p && sn.v == -s.v && sn.a == -s.a && sn.j == -s.j);
  }
  EXPECT_EQ(off, 0) << "of " << n + 1 << " samples not mirrored";
}

}  // namespace settle::test
