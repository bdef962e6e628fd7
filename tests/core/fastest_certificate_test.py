#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""tools/fastest-certificate proves a move the shortest, or says where the proof fails, on moves whose
answer is known without it:
- the rigid time-optimal move (no mode; the textbook answer): certified, its dual worth D;
- the same move with a switch moved (it no longer ends at D): refused as not one of the problem's;
- two such moves one after the other, with or without a dwell between (at rest, within the limits,
  and longer than the one move of twice the distance): not certified;
- grid case 237 as planned before session 23 (tests/core/data/fastest_plan_d05a305_case237.json:
  1.6078 s, at rest and within the limits; the reference reaches 1.5637 s): not certified, at its
  cruise, where the shorter move slows down; the same problem planned by SETTLE: certified, shorter;
- usage errors exit 2.
Usage: fastest_certificate_test.py TOOL SETTLE DATA_DIR"""
import json
import os
import subprocess
import sys
import tempfile


def rigid(d_scale=1.0, dwell=None):
    """D = 1 m (2 m with `dwell`), vmax 1 m/s, amax 2 m/s^2, jmax 10 m/s^3, no mode."""
    one = [(0.2, 10.0), (0.3, 0.0), (0.2, -10.0), (0.3 * d_scale, 0.0), (0.2, -10.0), (0.3, 0.0), (0.2, 10.0)]
    segs = one if dwell is None else one + ([(dwell, 0.0)] if dwell > 0 else []) + one
    params = {}
    for k, (d, j) in enumerate(segs):
        params[f"segment{k}_duration"], params[f"segment{k}_jerk"] = d, j
    req = {"profile": "fastest", "distance": 1.0 if dwell is None else 2.0, "vmax": 1.0, "amax": 2.0, "jmax": 10.0,
           "modes": []}
    return {"status": "ok", "family": "bang-bang", "duration": sum(d for d, _ in segs), "params": params,
            "request": req}


def check(tool, plan):
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump(plan, f)
    try:
        return subprocess.run([tool, "check", f.name], capture_output=True, text=True, check=False)
    finally:
        os.unlink(f.name)


def main():
    tool, settle, data = sys.argv[1], sys.argv[2], sys.argv[3]
    r = check(tool, rigid())
    assert r.returncode == 0 and r.stdout.startswith("certified"), r
    gap = float(r.stdout.split("gap")[1])
    assert abs(gap) < 1e-9, r.stdout
    r = check(tool, rigid(d_scale=1.1))
    assert r.returncode == 1 and "not one of the problem's" in r.stdout, r
    for dwell in (0.1, 0.0):
        r = check(tool, rigid(dwell=dwell))
        assert r.returncode == 1 and r.stdout.startswith("not certified"), (dwell, r)
        assert "not one of the problem's" not in r.stdout, (dwell, r)  # a move of the problem, longer
    old_path = os.path.join(data, "fastest_plan_d05a305_case237.json")
    r = subprocess.run([tool, "check", old_path], capture_output=True, text=True, check=False)
    assert r.returncode == 1 and "negative measure on the cruise" in r.stdout, r
    old = json.load(open(old_path, encoding="utf-8"))
    q = old["request"]
    argv = [settle, "plan", "--profile", "fastest", "--distance", str(q["distance"]), "--vmax", str(q["vmax"]),
            "--amax", str(q["amax"]), "--jmax", str(q["jmax"])]
    for m in q["modes"]:
        argv += ["--omega", str(m["omega"]), "--zeta", str(m["zeta"])]
    now = subprocess.run(argv + ["--json"], capture_output=True, text=True, check=True)
    r = subprocess.run([tool, "check", "-"], input=now.stdout, capture_output=True, text=True, check=False)
    assert r.returncode == 0 and r.stdout.startswith("certified"), r
    t_now, t_old = json.loads(now.stdout)["duration"], old["duration"]
    assert t_now < t_old * (1 - 0.02), (t_now, t_old)
    r = subprocess.run([tool, "grid", settle, os.devnull, "--every", "0"], capture_output=True, text=True, check=False)
    assert r.returncode == 2 and "--every" in r.stderr, r
    print(f"fastest-certificate: rigid move certified (gap {gap:.2g}); case 237 {t_old:.6f} s not certified, "
          f"{t_now:.6f} s certified")
    return 0


if __name__ == "__main__":
    sys.exit(main())
