// SPDX-License-Identifier: Apache-2.0
#pragma once
// Soak draw 263 of tests/core/test_halt.cpp (seed 36, SETTLE_HALT_CASES=1000; printed by
// SETTLE_PRINT_DRAW=263 settle_core_halt_soak): three path axes on three modes, `fastest`. Each axis
// planning its own halt, they came to rest up to 1.24 ms apart (halted at kDraw263HaltAt); the
// core, loop and CLI tests of a path halt planned once start from it.
#include "settle/core/multi_axis.hpp"
#include "settle/core/profiles/registry.hpp"

namespace settle::testing {

// Three path axes of profile `fastest`: distance, vmax, amax, jmax, omega, zeta per axis.
inline core::MultiAxisRequest fastest_path(const double (&ax)[3][6]) {
  core::MultiAxisRequest r{};
  r.count = 3;
  r.base.profile = core::ProfileKind::fastest;
  for (std::size_t i = 0; i < 3; ++i) r.axes[i] = {ax[i][0], ax[i][1], ax[i][2], ax[i][3], ax[i][4], ax[i][5]};
  return r;
}

inline constexpr double kDraw263HaltAt = 0.0024212589513964229;

inline core::MultiAxisRequest draw_263() {
  constexpr double ax[3][6] = {
      {0.046877826959013817, 1.3343700773070253, 5.6939743601786175, 72.423963929550368, 19.953536890205648,
       0.060106925516701104},
      {0.39871877719440468, 1.7552669291800269, 51.683884171226943, 1568.9084901034028, 9.9194784734744719,
       0.053491991819204734},
      {0.20916622835025947, 1.8629532581535093, 32.43688385243307, 1161.5765503498844, 23.023030517820793,
       0.070231598534253967}};
  return fastest_path(ax);
}

// Soak draw 923 (printed by SETTLE_PRINT_DRAW=923): three path axes on three modes, `fastest`,
// whose bang-bang chain the refinement (arc_refine) minimises. Each axis's command planned at its
// own scale, axis 0's was another chain, 10.7 ms shorter than the path's: a halt at kDraw923HaltAt
// was planned on each axis (not scaled copies to 1e-9), and axis 0 came to rest 10.7 ms early.
inline constexpr double kDraw923HaltAt = 0.38260959158991031;

inline core::MultiAxisRequest draw_923() {
  constexpr double ax[3][6] = {
      {-0.051656363796242777, 0.54990248343837633, 13.349668292462708, 202.00063856847484, 35.847522279124028,
       0.027523982315693165},
      {0.449835860119015, 1.0690176804587612, 19.776747374462527, 1421.7629920469878, 16.282255631702878,
       0.010971547916612555},
      {0.084540570593814646, 1.9588359454645348, 17.886211478436948, 762.19740641966598, 35.36445647986929,
       0.065598590097290715}};
  return fastest_path(ax);
}

}  // namespace settle::testing
