#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The settle wheel (python/make_wheel.py) as a user gets it: installed offline into a fresh venv
(--system-site-packages, so Debian's numpy is there), imported from the venv, never from the build
tree. Checks its licence metadata, that __version__ is what `settle --version` prints, and runs
test_python.py (plans, samples, simulations, refusals, the typed stub) with the venv's interpreter.
  test_wheel.py --wheel-dir DIR --settle SETTLE_CLI"""
import argparse
import os
import pathlib
import subprocess
import sys
import tempfile
import zipfile


def run(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        sys.exit(f"{cmd[0]} {' '.join(cmd[1:3])} ... failed ({r.returncode}):\n{r.stdout}{r.stderr}")
    return r.stdout


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--wheel-dir", required=True, type=pathlib.Path)
    ap.add_argument("--settle", required=True)
    a = ap.parse_args()
    wheels = sorted(a.wheel_dir.glob("settle-*.whl"))
    if len(wheels) != 1:
        sys.exit(f"expected one wheel in {a.wheel_dir}, found {[w.name for w in wheels]}")
    wheel = wheels[0]
    version = run([a.settle, "--version"]).split()[1]

    with zipfile.ZipFile(wheel) as z:
        names = z.namelist()
        meta = z.read(next(n for n in names if n.endswith(".dist-info/METADATA"))).decode()
    for needed in ("settle/__init__.py", "settle/__init__.pyi", "settle/py.typed"):
        if needed not in names:
            sys.exit(f"{wheel.name} lacks {needed}")
    if not any(n.startswith("settle/_settle") and n.endswith(".so") for n in names):
        sys.exit(f"{wheel.name} lacks the extension settle/_settle*.so")
    if not any(n.endswith(".dist-info/LICENSE") for n in names):
        sys.exit(f"{wheel.name} lacks the licence file")
    for line in (f"Version: {version}", "License: Apache-2.0",
                 "Classifier: License :: OSI Approved :: Apache Software License", "Requires-Dist: numpy"):
        if line not in meta.splitlines():
            sys.exit(f"{wheel.name}'s METADATA lacks '{line}':\n{meta}")

    with tempfile.TemporaryDirectory(prefix="settle-venv-") as tmp:
        venv = pathlib.Path(tmp) / "venv"
        run([sys.executable, "-m", "venv", "--system-site-packages", str(venv)])
        py = str(venv / "bin" / "python")
        env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
        run([py, "-m", "pip", "install", "--no-index", "--quiet", str(wheel)], env=env)
        check = ("import settle, sys; "
                 "assert settle.__file__.startswith(sys.prefix), settle.__file__; "
                 f"assert settle.__version__ == {version!r}, settle.__version__; "
                 "p = settle.plan(profile='scurve', distance=0.05, time=0.6, omega=22.0); "
                 "assert p['status'] == 'ok' and abs(p['duration'] - 0.6) < 1e-12, p; "
                 "print(settle.__version__, settle.__file__)")
        print(run([py, "-c", check], env=env, cwd=tmp), end="")
        here = pathlib.Path(__file__).with_name("test_python.py")
        r = subprocess.run([py, str(here), "--settle", a.settle], env=env, cwd=tmp)
        if r.returncode != 0:
            sys.exit(f"test_python.py in the venv failed ({r.returncode})")
    print(f"{wheel.name}: installed into a fresh venv, imported, version {version}")


if __name__ == "__main__":
    main()
