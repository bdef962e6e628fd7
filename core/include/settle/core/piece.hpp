#pragma once
// A profile's exact decomposition into pieces, in double: over a piece's phase s (0 at its start,
// 1 at its end) the position is  P(s) = sum_k c_k s^k + Im(Z e^{2 pi i s}),  a polynomial of degree
// at most kMaxPieceDegree plus one phasor. Each closed-form shape (ramp-cycloid, ramp-versine,
// piecewise jerk) describes itself this way from its own evaluator's segment table, and the
// fixed-point builder quantises exactly these pieces (core/src/fixed/motion_build.cpp).
#include <array>
#include <cstddef>

namespace settle::core {

inline constexpr std::size_t kMaxPieceDegree = 5;

struct Piece {
  double start{0.0};   // s: time of the piece's start on the profile's clock
  double length{0.0};  // s
  std::array<double, kMaxPieceDegree + 1> c{};  // position (move units) per power of the phase
  double zr{0.0}, zi{0.0};                       // Z: the phasor's amplitude (move units)
  bool trig{false};
};

}  // namespace settle::core
