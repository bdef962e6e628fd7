#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""tools/fastest-lp survives a solver that crashes: each LP runs in a child process of its own, so a
HiGHS method that dies (Debian 12's scipy 1.10 dies of SIGSEGV in the interior-point solve with
presolve on grid case 135) costs that method, and the next one gives the answer. Here the first
method is made to die of SIGSEGV; reach(T) must equal the one the solver gives without the crash,
and a crash of every method must be an error that names it, not the end of the process.
Usage: fastest_lp_crash_test.py TOOL"""
import importlib.machinery
import importlib.util
import os
import signal
import sys


def load(tool):
    loader = importlib.machinery.SourceFileLoader("fastest_lp", tool)
    spec = importlib.util.spec_from_loader("fastest_lp", loader)
    mod = importlib.util.module_from_spec(spec)
    loader.exec_module(mod)
    return mod


def main():
    flp = load(sys.argv[1])
    case = (0.1, 1.0, 20.0, 800.0, [(22.0, 0.0)])  # the reference case, above its 0.27090 s
    want = flp.reach(0.2709, *case, 200)
    real = flp.linprog

    def dies_first(*args, **kwargs):  # runs in the child: only it dies
        if (kwargs["method"], kwargs["options"]["presolve"]) == ("highs-ipm", True):
            os.kill(os.getpid(), signal.SIGSEGV)
        return real(*args, **kwargs)

    flp.linprog = dies_first
    got = flp.reach(0.2709, *case, 200)  # from the next method: interior point without presolve
    assert abs(got - want) <= 1e-7 * want, (got, want)

    def always_dies(*_args, **_kwargs):
        os.kill(os.getpid(), signal.SIGSEGV)

    flp.linprog = always_dies
    try:
        flp.reach(0.2709, *case, 200)
    except RuntimeError as e:
        assert "HiGHS crashed (SIGSEGV)" in str(e), e
    else:
        raise AssertionError("every method crashed and reach() returned")
    print(f"fastest-lp: a crashed method falls back; reach {got:.9g} (without the crash {want:.9g})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
