#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The `settle` Python module (python/), from the build tree or an install (PYTHONPATH picks it).
  test_python.py [--settle <settle CLI>]
Each check stands on its own: plan() against what `settle plan --json` prints, sample()'s end
against the distance and its velocity against its own position's differences, simulate()'s
residual against a Duhamel integral of sample()'s acceleration, and every refusal naming its
keyword."""
import argparse
import ast
import doctest
import itertools
import json
import math
import pathlib
import subprocess
import sys
import unittest

import numpy as np

import settle

SETTLE_CLI = None
OMEGA = 22.04871  # seed 000's beam, first mode
MOVES = [
    dict(profile="scurve", distance=0.05, time=0.8 * 2 * math.pi / OMEGA, omega=OMEGA),
    dict(profile="scurve-damped", distance=0.05, time=0.3, omega=OMEGA, zeta=0.05),
    dict(profile="ramp-versine", distance=0.02, time=0.5, omega=OMEGA),
    dict(profile="pseudopoly", distance=0.05, time=0.8, gammas=[3, 4, 5, 6], omega=OMEGA, shaper="zv"),
    dict(profile="poly345", distance=1.5, time=2.0),
    dict(profile="trapezoid", distance=1.0, vmax=1.0, amax=2.0),
    dict(profile="jerk-limited", distance=0.3, vmax=0.5, amax=2.0, jmax=40.0, shaper="ei", omega=30.0),
    dict(profile="trapezoid", distance=0.2, vmax=0.5, amax=2.0, shaper="ei3", omega=30.0, zeta=0.05),
]


def cli_args(move):
    args = []
    for key, value in move.items():
        if isinstance(value, list):
            value = ",".join(str(v) for v in value)
        args += ["--" + key, str(value)]
    return args


def cli_plan(out):
    """`settle plan --json` without its "request": the CLI's output is also a plan file for
    --plan-from, which the module's plan() (a plan, not a file) does not write."""
    j = json.loads(out)
    j.pop("request", None)
    return j


def json_like(value):
    """plan() reports an infinite peak as math.inf; the JSON writer prints it as null."""
    if isinstance(value, dict):
        return {k: json_like(v) for k, v in value.items()}
    if isinstance(value, list):
        return [json_like(v) for v in value]
    if isinstance(value, float) and math.isinf(value):
        return None
    return value


class Plan(unittest.TestCase):
    @unittest.skipUnless(SETTLE_CLI or "--settle" in sys.argv, "needs the settle CLI (--settle)")
    def test_plan_is_what_the_cli_prints(self):
        for move in MOVES:
            with self.subTest(profile=move["profile"]):
                out = subprocess.run([SETTLE_CLI, "plan", *cli_args(move), "--json"], capture_output=True,
                                     text=True, check=True).stdout
                # %.17g in the CLI's JSON round-trips: the same doubles, compared exactly.
                self.assertEqual(json_like(settle.plan(**move)), cli_plan(out))

    def test_plans_match_closed_forms(self):
        """Values derived here, not by Settle: the module and the CLI share their code, so comparing
        them cannot catch a wrong plan; these closed forms can."""
        d, t = 0.3, 0.6
        p = settle.plan(profile="poly345", distance=d, time=t)
        self.assertAlmostEqual(p["duration"], t, places=12)
        self.assertAlmostEqual(p["peaks"]["velocity"], 15 / 8 * d / t, places=9)  # s = 1/2
        self.assertAlmostEqual(p["peaks"]["acceleration"], 10 / math.sqrt(3) * d / t ** 2, places=9)
        self.assertAlmostEqual(p["peaks"]["jerk"], 60 * d / t ** 3, places=6)  # at s = 0
        # Trapezoid reaching vmax: ramp vmax/amax, cruise, ramp down: T = D/vmax + vmax/amax.
        d, vmax, amax = 1.0, 0.5, 2.0
        p = settle.plan(profile="trapezoid", distance=d, vmax=vmax, amax=amax)
        self.assertAlmostEqual(p["duration"], d / vmax + vmax / amax, places=9)
        self.assertAlmostEqual(p["peaks"]["velocity"], vmax, places=9)
        # Triangle (vmax not reached): T = 2 sqrt(D/amax).
        p = settle.plan(profile="trapezoid", distance=0.1, vmax=5.0, amax=2.0)
        self.assertAlmostEqual(p["duration"], 2 * math.sqrt(0.1 / 2.0), places=9)
        self.assertAlmostEqual(p["peaks"]["velocity"], math.sqrt(0.1 * 2.0), places=9)

    def test_profile_names_are_the_registrys_as_the_cli_lists_them(self):
        self.assertEqual(settle.PROFILES[0], "scurve")
        with self.assertRaises(ValueError) as caught:
            settle.plan(distance=1.0)
        self.assertEqual(str(caught.exception), "profile: required (" + ", ".join(settle.PROFILES) + ")")
        for name in settle.PROFILES:  # every name is taken: what is missing is then the distance
            with self.subTest(profile=name):
                self.assertRaisesRegex(ValueError, "^distance: required", lambda: settle.plan(profile=name))
        if SETTLE_CLI:
            out = subprocess.run([SETTLE_CLI, "plan", "--distance", "1"], capture_output=True, text=True)
            self.assertEqual(out.returncode, 2)
            self.assertIn("--profile: required (" + ", ".join(settle.PROFILES) + ")", out.stderr)

    @unittest.skipUnless(SETTLE_CLI or "--settle" in sys.argv, "needs the settle CLI (--settle)")
    def test_fastest_for_several_modes_and_robust_is_what_the_cli_prints(self):
        # omega and zeta as lists are --omega and --zeta repeated, one per mode, in order.
        base = dict(profile="fastest", distance=0.1, vmax=1.0, amax=20.0, jmax=800.0)
        two = dict(base, omega=[22.0, 60.0], zeta=[0.02, 0.01])
        robust = dict(base, omega=22.0, robust=10.0)
        for move, args in [(two, ["--omega", "22", "--zeta", "0.02", "--omega", "60", "--zeta", "0.01"]),
                           (robust, ["--omega", "22", "--robust", "10"])]:
            with self.subTest(move=move):
                rest = [a for k, v in base.items() for a in ("--" + k, str(v))]
                out = subprocess.run([SETTLE_CLI, "plan", *rest, *args, "--json"], capture_output=True, text=True,
                                     check=True).stdout
                self.assertEqual(json_like(settle.plan(**move)), cli_plan(out))
        self.assertEqual(settle.plan(**two)["profile"], "fastest")

    def test_shaped_duration_is_profile_plus_last_impulse(self):
        p = settle.plan(profile="scurve", distance=0.1, time=0.5, omega=10.0, shaper="zvd")
        impulses = p["shaper"]["impulses"]
        self.assertEqual(len(impulses), 3)
        self.assertAlmostEqual(sum(i["amplitude"] for i in impulses), 1.0, places=12)
        self.assertAlmostEqual(p["duration"], p["profile_duration"] + impulses[-1]["time"], places=12)
        # ZVD's impulses are half a damped period apart.
        self.assertAlmostEqual(impulses[1]["time"], math.pi / 10.0, places=9)


class Sample(unittest.TestCase):
    def test_arrays_cover_the_move_and_end_on_the_distance(self):
        for move in MOVES:
            with self.subTest(profile=move["profile"]):
                duration = settle.plan(**move)["duration"]
                s = settle.sample(dt=1e-3, **move)
                for key in ("t", "position", "velocity", "acceleration", "jerk"):
                    self.assertIsInstance(s[key], np.ndarray)
                    self.assertEqual(s[key].dtype, np.float64)
                    self.assertEqual(s[key].shape, (math.ceil(duration / 1e-3) + 1,))
                self.assertEqual(s["t"][0], 0.0)
                self.assertEqual(s["t"][-1], duration)
                self.assertEqual(s["position"][0], 0.0)
                self.assertEqual(s["position"][-1], move["distance"])
                self.assertEqual(s["velocity"][-1], 0.0)

    def test_velocity_is_the_derivative_of_position(self):
        move = dict(profile="poly345", distance=1.5, time=2.0)
        s = settle.sample(dt=1e-4, **move)
        t, p, v = s["t"][:-1], s["position"][:-1], s["velocity"][:-1]  # the last step may be short
        central = (p[2:] - p[:-2]) / (t[2:] - t[:-2])
        np.testing.assert_allclose(central, v[1:-1], atol=1e-6 * np.max(np.abs(v)))
        # 3-4-5 polynomial: peak velocity 15/8 D/T at mid-move.
        self.assertAlmostEqual(np.max(v), 15 / 8 * 1.5 / 2.0, places=6)


class Simulate(unittest.TestCase):
    def duhamel_residual(self, omega, move):
        """Residual amplitude of an undamped unit mode after the move: |∫ a(τ) e^{-iωτ} dτ| / ω."""
        s = settle.sample(dt=1e-5, **move)
        a = s["acceleration"] * np.exp(-1j * omega * s["t"])
        return abs(np.trapz(a, s["t"])) / omega

    def test_residual_matches_an_independent_duhamel_integral(self):
        omega = 12.0
        move = dict(profile="jerk-limited", distance=0.2, vmax=0.4, amax=1.5, jmax=20.0)
        r = settle.simulate(plant=[(omega, 0.0)], **move)
        expected = self.duhamel_residual(omega, move)
        self.assertGreater(expected, 1e-4)
        self.assertAlmostEqual(r["residual_amplitude"] / expected, 1.0, places=4)
        self.assertIsInstance(r["mode_residual"], np.ndarray)
        self.assertEqual(r["mode_residual"].shape, (1,))

    def test_a_move_designed_for_the_mode_leaves_it_at_rest(self):
        for omega in (8.0, 22.0, 40.0):
            with self.subTest(omega=omega):
                move = dict(profile="scurve", distance=0.05, time=0.5, omega=omega)
                designed = settle.simulate(plant=[(omega, 0.0)], **move)["residual_amplitude"]
                detuned = settle.simulate(plant=[(omega * 1.3, 0.0)], **move)["residual_amplitude"]
                self.assertLess(designed, 1e-9 * move["distance"])
                self.assertGreater(detuned, 1e3 * designed)

    @unittest.skipUnless(SETTLE_CLI or "--settle" in sys.argv, "needs the settle CLI (--settle)")
    def test_metrics_are_what_the_cli_prints(self):
        move = MOVES[0]
        out = subprocess.run([SETTLE_CLI, "simulate", "--plant", "beam", *cli_args(move), "--json"],
                             capture_output=True, text=True, check=True).stdout
        cli = json.loads(out)
        r = settle.simulate(plant="beam", **move)
        for key in ("residual_amplitude", "prv_percent", "step_residual", "peak_deflection", "final_energy",
                    "settling_time"):
            self.assertEqual(r[key], cli[key], key)
        self.assertEqual(list(r["mode_residual"]), [m["residual_amplitude"] for m in cli["modes"]])


class BadArguments(unittest.TestCase):
    def assertNames(self, keyword, call, error=ValueError):
        with self.assertRaises(error) as caught:
            call()
        self.assertTrue(str(caught.exception).startswith(keyword), f"{caught.exception!r} does not name {keyword}")

    def test_each_refusal_names_its_keyword(self):
        good = dict(profile="scurve", distance=0.05, time=0.5, omega=22.0)
        cases = [
            ("profile", dict(good, profile="warp")),
            ("profile", dict(good, profile=3)),
            ("distance", dict(good, distance=float("nan"))),
            ("distance", dict(good, distance="far")),
            ("time", dict(good, time=-1.0)),
            ("omega", dict(good, omega=0.0)),
            ("zeta", dict(good, zeta=1.5)),
            ("shaper", dict(good, shaper="zz")),
            ("vmax", dict(profile="trapezoid", distance=1.0, vmax=-1.0, amax=1.0)),
            ("gammas", dict(profile="pseudopoly", distance=1.0, time=1.0, gammas=[3.0])),
            ("y", dict(profile="ramp-versine", distance=1.0, time=1.0, omega=5.0, y=[0.5, 0.5])),
        ]
        for keyword, move in cases:
            with self.subTest(keyword=keyword, move=move):
                self.assertNames(keyword, lambda: settle.plan(**move))
        self.assertNames("distance", lambda: settle.plan(profile="scurve", time=1.0, omega=3.0))
        self.assertNames("dt", lambda: settle.sample(**good, dt=0.0))
        self.assertNames("dt", lambda: settle.sample(**good))
        self.assertNames("plant", lambda: settle.simulate(plant="moon", **good))
        self.assertNames("plant", lambda: settle.simulate(plant=[(22.0, 2.0)], **good))
        self.assertNames("unexpected keyword argument 'speed'", lambda: settle.plan(**good, speed=1.0), TypeError)
        # Several modes: profile fastest only, one zeta per omega, at most four; robust: fastest only.
        fastest = dict(profile="fastest", distance=0.1, vmax=1.0, amax=20.0, jmax=800.0)
        self.assertNames("omega", lambda: settle.plan(**dict(good, omega=[22.0, 60.0])))
        self.assertNames("zeta", lambda: settle.plan(**fastest, omega=[22.0, 60.0], zeta=[0.0, 0.1, 0.2]))
        self.assertNames("omega", lambda: settle.plan(**fastest, omega=[10.0] * 6))
        self.assertNames("omega", lambda: settle.plan(**fastest, omega=[22.0, float("nan")]))
        self.assertNames("robust", lambda: settle.plan(**good, robust=10.0))
        self.assertNames("robust", lambda: settle.plan(**fastest, omega=22.0, robust=-1.0))
        # A keyword the move would ignore is refused as the CLI refuses the option: scurve reads no
        # zeta (scurve-damped does), poly345 no gammas, vtol only the EI shapers; zeta needs omega.
        self.assertNames("zeta", lambda: settle.plan(**good, zeta=0.1))
        settle.plan(**dict(good, profile="scurve-damped"), zeta=0.1)
        self.assertNames("gammas", lambda: settle.plan(profile="poly345", distance=0.1, time=0.5, gammas=[3, 5, 7]))
        self.assertNames("vtol", lambda: settle.plan(**good, shaper="zv", vtol=0.1))
        self.assertNames("zeta", lambda: settle.plan(profile="scurve-damped", distance=0.1, time=0.5, zeta=0.1))

    def test_ranges_and_sizes_are_the_clis(self):
        """The CLI's option ranges and size bounds hold for the keywords too (one table,
        plant::move_range): what the CLI refuses, the module refuses before any work."""
        good = dict(profile="scurve", distance=0.05, time=0.5, omega=22.0)
        self.assertNames("distance", lambda: settle.plan(**dict(good, distance=1e308)))
        self.assertNames("omega", lambda: settle.plan(**dict(good, omega=1e-320)))
        self.assertNames("time", lambda: settle.plan(**dict(good, time=1e9)))
        self.assertNames("vtol", lambda: settle.plan(**good, shaper="ei", vtol=0.7))
        # Endless iterators are refused after the most the keyword takes, not read to the end.
        pseudo = dict(profile="pseudopoly", distance=1.0, time=1.0)
        self.assertNames("gammas", lambda: settle.plan(**pseudo, gammas=itertools.count(3)))
        self.assertNames("plant", lambda: settle.simulate(plant=((22.0, 0.01) for _ in itertools.count()), **good))
        self.assertNames("plant", lambda: settle.simulate(plant=[itertools.count(1)], **good))
        # settle sample's bound: at most 2e6 samples (2e7 here).
        self.assertNames("dt", lambda: settle.sample(**good, dt=0.5 / 2e7))
        self.assertIn(len(settle.sample(**good, dt=0.5 / 1e6)["t"]), (1000001, 1000002))


class Package(unittest.TestCase):
    """The package around the extension: version, documentation, and a stub whose signatures are
    the keywords each function really accepts (an unknown keyword is a TypeError)."""

    @unittest.skipUnless(SETTLE_CLI or "--settle" in sys.argv, "needs the settle CLI (--settle)")
    def test_version_is_the_clis(self):
        out = subprocess.run([SETTLE_CLI, "--version"], capture_output=True, text=True, check=True).stdout
        self.assertEqual(out, f"settle {settle.__version__}\n")

    def test_every_function_is_documented(self):
        self.assertIn("vibration-free", settle.__doc__)
        for name in ("plan", "sample", "simulate"):
            self.assertIn(name + "(", getattr(settle, name).__doc__)
        # The package's own example runs and prints what it says.
        self.assertEqual(doctest.testmod(settle).failed, 0)

    def stub(self):
        path = pathlib.Path(settle.__file__).with_name("__init__.pyi")
        self.assertTrue(path.with_name("py.typed").exists(), "py.typed is missing beside the stub")
        tree = ast.parse(path.read_text())
        return {f.name: f for f in tree.body if isinstance(f, ast.FunctionDef)}

    def test_stub_signatures_are_the_accepted_keywords(self):
        stub = self.stub()
        self.assertEqual(sorted(stub), ["plan", "sample", "simulate"])
        base = dict(profile="poly345", distance=0.1, time=0.5)
        for name, fn in stub.items():
            with self.subTest(function=name):
                self.assertEqual(fn.args.args, [], "keyword-only: no positional parameters")
                keywords = [a.arg for a in fn.args.kwonlyargs]
                required = [a.arg for a, d in zip(fn.args.kwonlyargs, fn.args.kw_defaults) if d is None]
                self.assertIsNotNone(fn.returns)
                self.assertTrue(all(a.annotation is not None for a in fn.args.kwonlyargs))
                func = getattr(settle, name)
                # Each keyword the stub names is accepted (any refusal is about its value, never a
                # TypeError for the keyword), and each required one is required.
                for k in keywords:
                    try:
                        func(**{**base, k: object()})
                    except TypeError as e:
                        self.fail(f"{name} refuses the stub's keyword {k}: {e}")
                    except ValueError:
                        pass
                for k in required:
                    args = {**base, "dt": 0.01, "plant": "sdof"}
                    args = {a: v for a, v in args.items() if a in keywords and a != k}
                    with self.assertRaisesRegex(ValueError, "^" + k + ": "):
                        func(**args)
                # ...and a keyword the stub does not name is refused.
                with self.assertRaises(TypeError):
                    func(**base, nosuch=1)


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--settle")
    args, rest = parser.parse_known_args()
    SETTLE_CLI = args.settle
    unittest.main(argv=[sys.argv[0], *rest])
