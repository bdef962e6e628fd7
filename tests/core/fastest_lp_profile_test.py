#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""tools/fastest-lp case ... --duration T --profile-out FILE writes the LP's move at T: one row
(t j a v) per step and the end, a move that starts and ends at rest, within the limits, whose
rows are the exact steps of the axis under constant jerk and whose distance is the printed
reach(T) times D. And --profile-out without --duration is a usage error (exit 2).
Usage: fastest_lp_profile_test.py TOOL"""
import os
import subprocess
import sys
import tempfile


def main():
    tool = sys.argv[1]
    d, v, a, j, steps, t_move = 0.1, 1.0, 20.0, 800.0, 200, 0.2709  # the reference case, above its 0.27090 s
    base = [tool, "--steps", str(steps), "case", "--distance", str(d), "--vmax", str(v), "--amax", str(a),
            "--jmax", str(j), "--mode", "22,0"]
    bad = subprocess.run(base + ["--profile-out", os.devnull], capture_output=True, text=True)
    assert bad.returncode == 2 and "--profile-out needs --duration" in bad.stderr, bad
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "move.txt")
        out = subprocess.run(base + ["--duration", str(t_move), "--profile-out", path], capture_output=True,
                             text=True, check=True)
        reach = float(out.stdout)
        with open(path, encoding="utf-8") as f:
            rows = [tuple(map(float, line.split())) for line in f if not line.startswith("#")]
    assert reach >= 1.0, reach  # above the shortest duration: the move covers D
    assert len(rows) == steps + 1, len(rows)
    dt = t_move / steps
    tol = 1e-6
    p = 0.0
    for k, (t, jk, ak, vk) in enumerate(rows):
        assert abs(t - k * dt) <= 1e-9, (k, t)
        assert abs(jk) <= j * (1 + tol) and abs(ak) <= a * (1 + tol) and -tol * v <= vk <= v * (1 + tol), rows[k]
        if k < steps:
            a1, v1 = rows[k + 1][2], rows[k + 1][3]
            assert abs(a1 - (ak + jk * dt)) <= tol * a, k  # the exact step under constant jerk
            assert abs(v1 - (vk + ak * dt + jk * dt * dt / 2)) <= tol * v, k
            p += vk * dt + ak * dt * dt / 2 + jk * dt ** 3 / 6
    assert abs(rows[0][2]) <= tol * a and abs(rows[0][3]) <= tol * v, rows[0]
    assert abs(rows[-1][2]) <= tol * a and abs(rows[-1][3]) <= tol * v, rows[-1]
    assert abs(p - reach * d) <= 1e-6 * d, (p, reach * d)
    print(f"fastest-lp profile: {len(rows)} rows, reach {reach:.9g}, distance {p:.9g} m")
    return 0


if __name__ == "__main__":
    sys.exit(main())
