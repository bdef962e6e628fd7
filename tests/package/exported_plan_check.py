#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""`settle export` end to end: a plan tuned by the host's settle, exported as headers in double,
float and fixed point, streamed; every tick's target of each stream must be within one count of
`settle sample --plan-from`'s position times the scale (rounded), and the last exactly on the target.
Cortex-M4F: examples/exported_plan built against the installed package, run under QEMU:
  exported_plan_check.py --settle CLI --work DIR --prefix P --toolchain F --source DIR
                         --run-image TOOL --timeout S
Host: the same stream loop (HOST_MAIN) compiled by the host compiler against the installed headers
and core library:
  exported_plan_check.py --settle CLI --work DIR --prefix P --cxx CXX"""
import argparse
import json
import pathlib
import shutil
import subprocess
import sys

COUNTS_PER_UNIT = 1e6  # settle export's default
PERIOD_S = 1e-3        # its default --period-us 1000
# The tuned move: two modes known to +-15 %, a 50 mm move in 0.4 s (the tuner picks a ramp-versine
# with a four-impulse shaper: pieces with phasors, and delayed copies to sum).
TUNE = ["tune", "--mode", "22,0.05", "--mode", "60,0.02", "--uncertainty", "15", "--distance", "0.05", "--time", "0.4"]


def run(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        sys.exit(f"{' '.join(map(str, cmd))}\nfailed ({r.returncode}):\n{r.stdout}{r.stderr}")
    return r.stdout


HOST_MAIN = r"""// The stream loop of examples/exported_plan/main.cpp, printing to stdout.
#include <cstdio>
#include "plan_double.hpp"
#include "plan_fixed.hpp"
#include "plan_float.hpp"
int main() {
  plan_double::Stream d{plan_double::kPlan, 0};
  plan_float::Stream f{plan_float::kPlan, 0};
  plan_fixed::Stream x{plan_fixed::kPlan, 0};
  bool last = false;
  for (int tick = 0; !last; ++tick) {
    bool lf = false, lx = false;
    const int pd = d.next(last), pf = f.next(lf), px = x.next(lx);
    if (lf != last || lx != last) return 1;
    std::printf("%d %d %d %d\n", tick, pd, pf, px);
  }
  return 0;
}
"""


def cortex_m4f(a, plan, work):
    """The example's console: its lines of targets."""
    build = work / "build"
    run(["cmake", "-S", a.source, "-B", str(build), "-G", "Ninja", f"-DCMAKE_TOOLCHAIN_FILE={a.toolchain}",
         f"-DCMAKE_PREFIX_PATH={a.prefix}", f"-DSETTLE_CLI={a.settle}", f"-DPLAN_FILE={plan}",
         "-DCMAKE_BUILD_TYPE=Release"])
    run(["cmake", "--build", str(build)])
    run([a.run_image, "--machine", "mps2-an386", "--timeout", a.timeout, "--workdir", str(work / "run"),
         "--expect", "console.txt:^exported_plan: [0-9]+ ticks", str(build / "exported_plan.elf")])
    return (work / "run" / "console.txt").read_text()


def host(a, plan, work):
    """HOST_MAIN's output, built against the installed package (headers and libsettle_core.a)."""
    for scalar in ("double", "float", "fixed"):
        (work / f"plan_{scalar}.hpp").write_text(
            run([a.settle, "export", "--plan-from", str(plan), "--scalar", scalar, "--name", f"plan_{scalar}"]))
    (work / "main.cpp").write_text(HOST_MAIN)
    prefix = pathlib.Path(a.prefix)
    libs = sorted(prefix.glob("lib*/libsettle_core.a"))
    if not libs:
        sys.exit(f"no libsettle_core.a under {prefix}")
    exe = work / "stream"
    run([a.cxx, "-std=c++20", "-O2", "-Wall", "-Wextra", "-Werror", "-Wconversion", f"-I{prefix / 'include'}",
         f"-I{work}", str(work / "main.cpp"), str(libs[0]), "-o", str(exe)])
    return run([str(exe)])


def main():
    ap = argparse.ArgumentParser()
    for opt in ("--settle", "--prefix", "--work"):
        ap.add_argument(opt, required=True)
    for opt in ("--toolchain", "--source", "--run-image", "--timeout", "--cxx"):
        ap.add_argument(opt)
    a = ap.parse_args()
    work = pathlib.Path(a.work)
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    plan = work / "tune.json"
    plan.write_text(run([a.settle, *TUNE, "--json"]))
    console = host(a, plan, work) if a.cxx else cortex_m4f(a, plan, work)

    rows = json.loads(run([a.settle, "sample", "--plan-from", str(plan), "--dt", str(PERIOD_S), "--json"]))["rows"]
    expected = [round(r[1] * COUNTS_PER_UNIT) for r in rows]  # position column (a tie may round either way: 1 count)
    streamed = []
    for line in console.splitlines():
        parts = line.split()
        if len(parts) == 4 and all(p.lstrip("-").isdigit() for p in parts):
            streamed.append([int(p) for p in parts])
    if len(streamed) != len(expected):
        sys.exit(f"the image streamed {len(streamed)} ticks; settle sample has {len(expected)} samples")
    for col, scalar in ((1, "double"), (2, "float"), (3, "fixed")):
        worst = max(abs(s[col] - e) for s, e in zip(streamed, expected))
        tick = max(range(len(expected)), key=lambda i: abs(streamed[i][col] - expected[i]))
        print(f"{scalar}: {len(expected)} ticks, largest difference from settle sample {worst} count(s) at tick {tick}")
        if worst > 1:
            sys.exit(f"{scalar}: tick {tick} streamed {streamed[tick][col]}, settle sample gives {expected[tick]}")
        if streamed[-1][col] != expected[-1]:
            sys.exit(f"{scalar}: the last target {streamed[-1][col]} is not the move's {expected[-1]}")
    print(f"exported_plan ({'host' if a.cxx else 'cortex-m4f'}): every stream within one count of settle sample, "
          "each ending on the target")


if __name__ == "__main__":
    main()
