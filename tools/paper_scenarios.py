#!/usr/bin/env python3
"""The three papers' streaming scenarios, in one place: tools/demo-run streams every one of them and
prints the table, tests/e2e/e2e.py checks each of them on vcan0 (ctest -L vcan).

  tools/paper_scenarios.py [--gammas G1,G2,G3]     # one line per scenario:
                                                   # id|label|plant options|move options|axis vmax|out scale
  tools/paper_scenarios.py --ids                   # the ids alone, one per line (ctest's test names)
  tools/paper_scenarios.py --paper-gammas          # seed 004's published exponents (the default)

Seed 000: the Table 1 beam (3 modes), first mode 22.04871 rad/s. The paper gives no distance; as in
`settle reproduce 000` (docs/simulation.md), D = 0.07 m puts the S-curve's peak velocity at the
paper's 1 m/s actuator limit at T = Tn/2, so every move here stays within it. Seed 001: the
mass-spring-damper at tau = 0.167 s, the computed input against the paper's arbitrary Y. Seed 004:
the belt platform (D in motor radians, the residual in platform radians, lambda = 1/30), the
optimised exponents (the paper's unless given) against 3-4-5. `out scale` is the move's size in
the units its residual is measured in: the scale of the CAN-versus-offline agreement."""
import math, sys

W000 = 22.04871
TN000 = 2 * math.pi / W000
PAPER_GAMMAS = "3.024,4.565,5.874"


def scenarios(gammas=PAPER_GAMMAS):
    """[(id, label, plant args, move args, axis vmax, out scale)], in the demo table's order."""
    beam, sdof = ["--plant", "beam"], ["--plant", "sdof"]
    belt = ["--plant", "belt", "--load-counts-per-unit", "1e6"]
    rows = []
    for frac in (0.8, 1.75):
        t = f"{frac * TN000:.9f}"
        label = f"000 beam {frac:g} Tn"
        rows.append((f"000-scurve-{frac:g}", label, beam,
                     ["--profile", "scurve", "--distance", "0.07", "--time", t, "--omega", f"{W000}"], 1, 0.07))
        rows.append((f"000-poly345-{frac:g}", label, beam, ["--profile", "poly345", "--distance", "0.07", "--time", t],
                     1, 0.07))
    ramp = ["--profile", "ramp-versine", "--distance", "0.1", "--time", "0.167"]
    rows.append(("001-computed", "001 sdof tau 0.167", sdof, ramp + ["--omega", "28.2842712", "--zeta", "0.1590990"],
                 2, 0.1))
    rows.append(("001-arbitrary", "001 sdof tau 0.167", sdof, ramp + ["--y", "0.5,0.25,0.25"], 2, 0.1))
    d004 = f"{15 * 2 * math.pi:.7f}"  # 15 motor revolutions
    rows.append(("004-optimised", "004 belt 15 rev 1 s", belt,
                 ["--profile", "pseudopoly", "--distance", d004, "--time", "1", "--gammas", gammas], 200,
                 float(d004) / 30))
    rows.append(("004-poly345", "004 belt 15 rev 1 s", belt, ["--profile", "poly345", "--distance", d004, "--time", "1"],
                 200, float(d004) / 30))
    return rows


if __name__ == "__main__":
    g = PAPER_GAMMAS
    args = sys.argv[1:]
    if args == ["--paper-gammas"]:
        print(PAPER_GAMMAS)
        sys.exit(0)
    if args == ["--ids"]:
        print("\n".join(row[0] for row in scenarios()))
        sys.exit(0)
    if args[:1] == ["--gammas"] and len(args) == 2:
        g = args[1]
    elif args:
        sys.exit("usage: tools/paper_scenarios.py [--gammas G1,G2,G3 | --ids | --paper-gammas]")
    for id_, label, plant, move, vmax, scale in scenarios(g):
        print("|".join([id_, label, " ".join(plant), " ".join(move), str(vmax), repr(scale)]))
