// SPDX-License-Identifier: Apache-2.0
#pragma once
// The integral of a profile against a mode's exponential, F(te) = int_0^te e^{lambda (te - u)} p(u) du:
// exactly, piece by piece, where the profile has pieces (piece.hpp), by Gauss-Legendre quadrature
// otherwise (the pseudo-polynomial). Private to core: the residual (residual.hpp) and the online
// blends (online.cpp) are built on it. Defined in residual.cpp.
#include <algorithm>
#include <cmath>

#include "numeric/complex.hpp"
#include "numeric/quadrature.hpp"
#include "settle/core/piece.hpp"
#include "settle/core/residual.hpp"

namespace settle::core::detail {

using numeric::Cx;

// phi1(x) = (e^x - 1) / x and phi2(x) = (e^x - 1 - x) / x^2, by their series near 0 where the
// closed forms cancel. Given ex = cexp(x), read only where the closed form is taken (|x| >= 0.5,
// resp. 1; pass anything otherwise): the blend's system has the exponential already.
[[nodiscard]] Cx phi1(Cx x, Cx ex) noexcept;
[[nodiscard]] Cx phi2(Cx x, Cx ex) noexcept;
// phi1 computing its own exponential where it needs one.
[[nodiscard]] Cx phi1(Cx x) noexcept;

// One piece's share of F(te1) and, when `both`, of F(te2) (profile_integrals; body: min(te, the
// profile's duration)), added to acc1 and acc2. Out of line: each profile's loop only calls it.
// `ended`, when given (one integral only): the piece's sum at its end (piece_sum, ended_piece_sums),
// read instead of taken again where the piece has ended by te1 (the same sum, to the bit).
void add_piece(const Piece& pc, Cx lam, double te1, double te2, double body1, double body2, bool both, Cx& acc1,
               Cx& acc2, const ModeMemory* ended = nullptr) noexcept;
// The share of F(te) past the profile's end tp (p = distance there), added to acc when te > tp.
void add_rest(double distance, double tp, double te, Cx lam, Cx& acc) noexcept;

// A move's memory Q (residual.hpp) at two times at once (a switch and the move's end: online_request),
// each the same to the bit as mode_memory(m, t, mode): the pieces that end before both are summed once.
void mode_memory_pair(const Move<double>& m, double t1, double t2, const Mode& mode, ModeMemory& q1,
                      ModeMemory& q2) noexcept;

// The sums of the first pieces of m's profile for the mode, each taken at its piece's end: what the
// mode's memory at any time after that end reads of the piece (for every shaper impulse alike). Up
// to n of them into out; returns how many (0 for a profile without pieces or a mode out of range).
int ended_piece_sums(const Move<double>& m, const Mode& mode, ModeMemory* out, int n) noexcept;
// mode_memory(m, t, mode), the same to the bit, reading the sums of the first n pieces
// (ended_piece_sums) where a piece has ended instead of taking them again.
[[nodiscard]] ModeMemory mode_memory_ended(const Move<double>& m, double t, const Mode& mode, const ModeMemory* ended,
                                           int n) noexcept;

// F(te1) = int_0^te1 e^{lambda (te1 - u)} p(u) du for an unshaped profile (p = D past its end), and
// when `both` F(te2) too, each the same to the bit as alone: a piece clipped alike at both (it ends
// before either) is summed once, and only the factor that refers its sum to each te is taken twice
// (a move's memory at the switch and at its end, online_request). One loop for one integral or two,
// so that a profile's pieces are expanded once in the code (the Cortex-M cores' flash).
// The sums of its first n_ended pieces at their ends (ended_piece_sums), when given, are read for
// the pieces that have ended by te1 (one integral only).
template <typename Shape>
void profile_integrals(const Shape& prof, Cx lam, double te1, double te2, bool both, Cx& f1, Cx& f2,
                       const ModeMemory* ended = nullptr, int n_ended = 0) noexcept {
  const double tp = prof.duration();
  Cx acc1{}, acc2{};
  const double body1 = std::min(te1, tp), body2 = std::min(te2, tp);
  if constexpr (requires { prof.piece_count(); }) {
    for (int i = 0; i < prof.piece_count(); ++i) {
      add_piece(prof.piece(i), lam, te1, te2, body1, body2, both, acc1, acc2, i < n_ended ? ended + i : nullptr);
    }
  } else {
    // No exact pieces (the pseudo-polynomial): composite Gauss-Legendre on panels short against
    // the mode's time scale, so that the exponential is resolved to rounding.
    const auto quadrature = [&](double te, double body, Cx& acc) {
      if (!(body > 0.0)) return;
      const int panels = std::clamp(static_cast<int>(std::ceil(cabs_max(lam) * body)) * 2, 32, 512);
      numeric::gauss_legendre_8(0.0, body, panels,
                                [&](double u, double w) { acc = acc + (w * prof.at(u).p) * cexp((te - u) * lam); });
    };
    quadrature(te1, body1, acc1);
    if (both) quadrature(te2, body2, acc2);
  }
  add_rest(prof.distance(), tp, te1, lam, acc1);
  if (both) add_rest(prof.distance(), tp, te2, lam, acc2);
  f1 = acc1;
  f2 = acc2;
}

// F(te) alone.
template <typename Shape>
[[nodiscard]] Cx profile_integral(const Shape& prof, Cx lam, double te) noexcept {
  Cx f{}, unused{};
  profile_integrals(prof, lam, te, te, false, f, unused);
  return f;
}

}  // namespace settle::core::detail
