#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Hostile arguments for every settle command (issue 12, "a test suite for hostile arguments").

A seeded generator builds argument vectors from a fast, valid base per command and one to three
mutations: NaN, +-inf, 1e308, -0, huge integers, empty strings, missing values, unknown and
duplicate options, absurd sizes, stray arguments. Each vector is run as a subprocess (an argv
list, no shell) and must hold:

  - no signal, no sanitizer report on stderr, at most 10 s of CPU, at most 512 MB resident;
  - exit 0 only with finite output (no nan/inf in stdout; with --json a JSON object, status ok);
  - exit 2 with nothing on stdout and exactly one stderr line "settle: error: <option>: ..." that
    names an option of the command or one given on the command line (with --json: the JSON
    error object and its "parameter");
  - exit 1 only for the documented runtime failures: a bus that cannot be opened (plant, stream,
    drive), a move that did not complete (stream, which then still reports), a file that cannot be
    written, a drive that aborts a transfer or does not answer (drive: the CiA 301 abort code).

A command of two words ("drive read") is two arguments.

The options each command accepts are read from its own --help (not from the C++ table), so an
option missing from the help is never tested and shows up in the help test instead.

  hostile_args.py --settle PATH [--seed N] [--count N]
"""
import argparse
import json
import os
import random
import re
import subprocess
import sys
import resource
import signal
import tempfile
import threading

# The time rules are on the process's own CPU time (user + system, from wait4), which a busy
# machine does not stretch: a run that waits for the CPU is not a slow run. A refusal (exit 2)
# or a failure (exit 1) must come within 10 s of CPU. Under ASan/UBSan settle runs about 10 times
# slower: a valid run (exit 0) at a size bound, or a valid `reproduce 001` (0.7 s release), may
# take up to 120 s of CPU there.
TIME_LIMIT_S = 10.0
SANITIZED_LIMIT_S = 120.0
# The wall-clock bound only stops a hang (a process that neither works nor ends): far beyond
# any CPU limit, so that a loaded machine's queueing never reaches it.
WALL_FACTOR = 20.0
RSS_LIMIT_KB = 512 * 1024

# Values no option should take silently.
HOSTILE = [
    "nan", "NaN", "-nan", "inf", "-inf", "Infinity", "1e308", "-1e308", "1e400", "-1e400", "-0", "0", "-0.0",
    "1e-320", "4.9e-324", "1e-300", "99999999999999999999", "-9223372036854775809", "18446744073709551616",
    "2147483648", "4294967296", "-1", "1.5", "0.5", "", "abc", "1e", "1e+", "0x10", "0x1p3", "1,2,3,", ",", "1,,2",
    " 1", "1 ", "+1", "--", "-", "\u00e9", "\x7f", "x" * 5000, "1e5", "3600", "1e-9", "1e6", "127", "128", "255",
    "256", "65535", "65536", "1,2,3", "1,0.5,1", "3,4,5,6,7,8,9,10,11", "nan,0.1,1", "1e308,0,1",
]

# A fast valid command line per command; mutations start from these.
BASE = {
    "plan": ["--profile", "poly345", "--distance", "0.1", "--time", "1"],
    "sample": ["--profile", "poly345", "--distance", "0.1", "--time", "1", "--dt", "0.05"],
    "simulate": ["--plant", "sdof", "--profile", "poly345", "--distance", "0.1", "--time", "0.5"],
    "reproduce": ["001"],
    # The interface does not exist: plant validates everything, then fails to open it (exit 1).
    "plant": ["--bus", "settle-hostile0", "--duration", "0.2"],
    "stream": ["--bus", "loopback", "--profile", "poly345", "--distance", "0.01", "--time", "0.1"],
    "tune": ["--mode", "12.566,0.03", "--uncertainty", "10", "--distance", "0.1", "--time", "0.5"],
    "identify": ["--bus", "loopback", "--plant", "sdof", "--hold", "0.5"],
    # settle drive against the simulated drive in its own process.
    "drive info": ["--bus", "loopback", "--node", "2"],
    "drive read": ["--bus", "loopback", "--index", "0x6041", "--type", "u16"],
    "drive write": ["--bus", "loopback", "--index", "0x6065", "--type", "u32", "--value", "5000"],
    "drive scan": ["--bus", "loopback", "--timeout-ms", "50"],
    "drive config": ["--bus", "loopback", "--eds", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                                                "hal", "eds", "split_rpdo_drive.eds")],
    # Its command word is a positional argument: the mutations remove it, repeat it and add strays.
    "drive nmt": ["stop", "--bus", "loopback", "--node", "3"],
}
# A coordinated move (--axes N, docs/multi_axis.md): count / 5 further runs of plan, sample,
# simulate and stream start from these, so that the per-axis lists and --sync are mutated too.
AXES_BASE = {
    "plan": ["--axes", "3", "--profile", "jerk-limited", "--distance", "0.1,0.05,-0.2", "--omega", "22,30,15",
             "--vmax", "1", "--amax", "20,10,40", "--jmax", "800"],
    "sample": ["--axes", "2", "--sync", "time", "--profile", "poly345", "--distance", "0.1,-0.05", "--time", "1",
               "--dt", "0.05"],
    "simulate": ["--axes", "2", "--plant", "sdof", "--profile", "scurve", "--distance", "0.1,0.05", "--vmax", "1",
                 "--amax", "20", "--jmax", "800", "--omega", "28,20"],
    # Two simulated drives on the loopback bus (two axes fit 1 Mbit/s at 1 kHz), on nodes of its own.
    "stream": ["--bus", "loopback", "--axes", "2", "--profile", "poly345", "--distance", "0.01,-0.02", "--time", "0.1",
               "--nodes", "3,7", "--settle-time", "0.1"],
}
WEIGHT = {"plan": 20, "sample": 14, "simulate": 26, "reproduce": 6, "plant": 12, "stream": 22, "tune": 12, "identify": 8,
          "drive info": 4, "drive read": 6, "drive write": 8, "drive scan": 3, "drive config": 5, "drive nmt": 4}

# The commands `settle --help` lists that BASE does not draw, and why. Any other command it lists
# and BASE lacks fails the run, so that a new command is drawn from the day it exists.
NOT_DRAWN = {
    "demo": "runs every paper scenario as processes (minutes a run); tests/e2e/demo_test.py holds it",
    "export": "its base needs a plan file (--plan-from) made first; tests/app/test_cli_export.cpp holds its refusals",
}
LISTED = re.compile(r"^  (drive [a-z]+|[a-z]+) ", re.M)

# What an error about a command's positional argument names (reproduce's experiment, drive nmt's
# command word).
POSITIONAL = {"reproduce": "experiment", "drive nmt": "command"}

# Sizes no run may honour; each must be refused before any work (exit 2).
ABSURD = {
    "plan": [["--time", "1e300"], ["--distance", "1e300"], ["--vmax", "1e-300"], ["--axes", "9"],
             ["--distance", "1,2,3,4,5,6,7,8,9"], ["--vmax", "1e-300,1,1"], ["--axes", "1e9"]],
    "sample": [["--dt", "5e-9"], ["--dt", "1e-300"], ["--dt", "4.9e-324"], ["--time", "3600", "--dt", "1e-4"],
               ["--axes", "8", "--dt", "1e-6"]],
    "simulate": [["--tail", "1e6"], ["--tail", "1e300"], ["--dt", "1e-7"], ["--time", "3600"],
                 ["--tail", "3000", "--time", "1000", "--csv", "@TMP@/h.csv"], ["--dt", "1e-6", "--csv", "@TMP@/h.csv"],
                 ["--modes", "1e9"], ["--plant", "beam", "--modes", "100000"], ["--axes", "8", "--dt", "1e-6"]],
    "reproduce": [["--out", ""]],
    "plant": [["--duration", "1e300"], ["--sync-loss-periods", "1e9"], ["--period-us", "1e12"]],
    "stream": [["--time", "1e5"], ["--time", "3000"], ["--time", "900", "--period-us", "100"], ["--settle-time", "1e9"],
               ["--distance", "1e6"], ["--counts-per-unit", "1e9", "--distance", "10"], ["--time", "1e300"],
               ["--bitrate", "10000"], ["--bitrate", "1e300"], ["--period-us", "100", "--bitrate", "1000000"],
               ["--axes", "3", "--distance", "0.01,0.01,0.01"], ["--axes", "8", "--distance", "1,1,1,1,1,1,1,1"],
               ["--nodes", "1,2,3,4,5,6,7,8,9"]],
    "tune": [["--mode", "1e6,0.01", "--time", "3600"], ["--time", "3600"], ["--uncertainty", "1e300"],
             ["--uncertainty", "90", "--time", "3000"], ["--modes-from", "@TMP@/absent.json"], ["--png", "@TMP@/t.svg"]],
    "identify": [["--hold", "1e9"], ["--distance", "1e300"], ["--max-modes", "1e9"], ["--hold", "600", "--period-us", "100"],
                 ["--noise", "1e300"], ["--distance", "1000", "--vmax", "1e-6"]],
    "drive info": [["--timeout-ms", "1e9"], ["--node", "1e300"]],
    "drive read": [["--index", "0x100000000"], ["--index", "0xFFFFFFFFFFFFFFFFFFFF"], ["--sub", "1e9"],
                   ["--timeout-ms", "99999999999999999999"]],
    "drive write": [["--type", "string", "--value", "x" * 5000], ["--type", "i32", "--value", "-2147483649"],
                    ["--type", "u32", "--value", "0x1FFFFFFFF"], ["--value", "1e300"]],
    "drive scan": [["--timeout-ms", "1e9"], ["--timeout-ms", "4.9e-324"]],
    "drive config": [["--timeout-ms", "1e9"], ["--node", "1e300"], ["--eds", ""]],
    "drive nmt": [["--timeout-ms", "1e9"], ["--node", "1e300"], ["--node", "0"], ["--timeout-ms", "4.9e-324"]],
}

# What a drive command's exit 1 may say: the bus, or the drive's answer (text on stderr, or the
# JSON error object's code).
# The codes of a runtime failure's JSON error object (app/options.hpp, report_failure).
RUNTIME_FAILURE_CODES = {"bus", "run_failed", "write_failed"}
DRIVE_FAILURES = re.compile(r"cannot open|SDO abort 0x[0-9A-F]{8} \(|no answer within|holds \d+ bytes; --type|"
                            r"^settle drive config: node \d+: |"
                            r"^settle drive nmt: node \d+: (its heartbeat says|the NMT command could not be sent)")
DRIVE_FAILURE_CODES = {"bus", "sdo_abort", "sdo_timeout", "type_mismatch", "read_back_differs", "cannot_stream",
                       "start_up_failed", "timeout", "plan_too_long", "nmt_state", "send_failed"}

# settle identify's runtime refusals (docs/identification.md): one line ending in its code.
IDENTIFY_FAILURE_CODES = {"bus_unavailable", "run_failed", "drive_not_enabled", "excitation_not_completed",
                          "feedback_incomplete", "no_load_feedback", "response_too_small", "free_response_too_short",
                          "no_motion", "figure_failed"}
IDENTIFY_FAILURES = re.compile(r"^settle identify: .+ \[(" + "|".join(sorted(IDENTIFY_FAILURE_CODES)) + r")\]$", re.M)

SANITIZER = re.compile(r"AddressSanitizer|LeakSanitizer|UndefinedBehaviorSanitizer|runtime error:|MemorySanitizer")
NON_FINITE = re.compile(r"(?i)(?<![a-z])-?(nan|inf|infinity)(?![a-z])")
# An option's own line starts two spaces in; its wrapped description lines further in.
OPTION_LINE = re.compile(r"^  (?:-h,)?(--[A-Za-z][A-Za-z0-9-]*)(?:\s+(\S+))?")


def help_options(settle, command):
    """{option: placeholder} from `settle <command> --help` ("" for a flag)."""
    r = subprocess.run([settle, *command.split(), "--help"], capture_output=True, text=True, timeout=30)
    if r.returncode != 0:
        sys.exit(f"settle {command} --help exited {r.returncode}")
    opts = {}
    for line in r.stdout.splitlines():
        m = OPTION_LINE.match(line)
        if m and m.group(1) != "--help":
            ph = m.group(2) or ""
            opts[m.group(1)] = ph if ph.isupper() or "," in ph else ""
    if not opts:
        sys.exit(f"settle {command} --help lists no options")
    return opts


def run(argv, cwd, limit):
    """(exit status or -signal, max RSS in kB, CPU seconds, stdout bytes, stderr bytes, over limit).
    Over limit: killed after `limit` s of CPU (RLIMIT_CPU) or WALL_FACTOR x `limit` of wall time."""
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        # In a scratch directory: a hostile value given to --out, --csv or --log is a relative path.
        cpu_limit = int(limit) + 1

        def limit_cpu():  # in the child, before exec: SIGXCPU past the CPU limit, SIGKILL 1 s on
            resource.setrlimit(resource.RLIMIT_CPU, (cpu_limit, cpu_limit + 1))

        p = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=out, stderr=err, cwd=cwd, preexec_fn=limit_cpu)
        timed_out = []

        def kill():
            timed_out.append(True)
            p.kill()

        timer = threading.Timer(limit * WALL_FACTOR, kill)
        timer.start()
        _, status, usage = os.wait4(p.pid, 0)
        timer.cancel()
        p.returncode = 0  # reaped here (wait4 gives the child's own rusage); keep Popen quiet
        elapsed = usage.ru_utime + usage.ru_stime
        if os.WIFSIGNALED(status) and os.WTERMSIG(status) in (signal.SIGXCPU, signal.SIGKILL) and elapsed >= limit:
            timed_out.append(True)
        out.seek(0)
        err.seek(0)
        code = -os.WTERMSIG(status) if os.WIFSIGNALED(status) else os.WEXITSTATUS(status)
        return code, usage.ru_maxrss, elapsed, out.read(), err.read(), bool(timed_out)


def typo(rng, name):
    s = list(name[2:])
    k = rng.randrange(3)
    i = rng.randrange(len(s))
    if k == 0 and len(s) > 1:
        del s[i]
    elif k == 1:
        s.insert(i, rng.choice("abcdefghijklmnopqrstuvwxyz-"))
    else:
        s[i] = rng.choice("abcdefghijklmnopqrstuvwxyz")
    return "--" + "".join(s)


def set_option(args, name, value, replace=True):
    if replace and name in args:
        i = args.index(name)
        if i + 1 < len(args):
            args[i + 1] = value
            return
    args += [name, value]


def mutate(rng, command, opts, args, tmp):
    names = sorted(opts)
    # reproduce --out DIR renders figures (seconds, through gnuplot): any non-empty DIR is valid,
    # so its hostile values are the empty and the missing one (ABSURD, kind 6), not paths.
    valued = [n for n in names if opts[n]]
    flags = [n for n in names if not opts[n]]
    kind = rng.randrange(12)
    if kind <= 3:  # a hostile value for any option that takes one
        set_option(args, rng.choice(valued), rng.choice(HOSTILE), replace=rng.random() < 0.7)
    elif kind == 4:  # a number anywhere from tiny to huge, either sign
        v = rng.choice([10 ** rng.uniform(-15, 15), -(10 ** rng.uniform(-15, 15)), rng.randint(-300, 300)])
        name = rng.choice(valued)
        if command == "stream" and name in ("--time", "--settle-time", "--period-us", "--vmax", "--amax", "--jmax",
                                            "--omega") or \
                command == "identify" and name in ("--hold", "--period-us", "--distance", "--vmax", "--amax", "--jmax"):
            v = rng.choice(["-1", "0", "1e300", "nan"])  # valid large sizes make valid, long streams
        set_option(args, name, str(v))
    elif kind == 5:  # a duplicate
        present = [a for a in args if a.startswith("--")] or names
        n = rng.choice(present)
        args += [n] + ([] if not opts.get(n) else [args[args.index(n) + 1] if n in args and args.index(n) + 1 < len(args) else "1"])
    elif kind == 6:  # a value missing at the end, or followed by another option
        n = rng.choice(valued)
        if rng.random() < 0.5:
            args.append(n)
        else:
            args[0:0] = [n]
    elif kind == 7:  # an unknown option: a typo of a real one, or junk
        args += [typo(rng, rng.choice(names)) if rng.random() < 0.7 else rng.choice(["--", "-x", "-inf", "--x=1", "---time"]),
                 rng.choice(["1", "nan", ""])]
    elif kind == 8:  # a required piece removed
        if len(args) >= 2:
            i = rng.randrange(0, len(args) - 1)
            del args[i:i + 2]
    elif kind == 9:  # absurd sizes
        extra = [a.replace("@TMP@", tmp) for a in rng.choice(ABSURD[command])]
        for i in range(0, len(extra), 2):
            set_option(args, extra[i], extra[i + 1])
    elif kind == 10:  # flags and = forms
        choice = rng.randrange(5)
        if choice == 0 and flags:
            args.append(rng.choice(flags) + "=1")
        elif choice == 1:
            args.append(rng.choice(valued) + "=")
        elif choice == 2:
            args.append(rng.choice(valued) + "=" + rng.choice(HOSTILE))
        elif choice == 3:
            args.insert(rng.randrange(len(args) + 1), rng.choice(["stray", "1", "", "-", "--json"]))
        else:
            args += ["--mode", "10,0.01,1"] * rng.choice([65, 2000])
    else:  # JSON output (errors too)
        args.append("--json")
    if command == "reproduce":
        # reproduce --out DIR renders figures through gnuplot (seconds): any non-empty DIR is
        # valid, so the hostile --out values are the empty and the missing one, never a path.
        for i, x in enumerate(args):
            if x == "--out" and i + 1 < len(args) and not args[i + 1].startswith("--"):
                args[i + 1] = ""
            elif x.startswith("--out="):
                args[i] = "--out="
    return args


def check(command, argv, opts, result):
    """The reason the run broke a rule, or None."""
    code, rss, elapsed, out, err, timed_out = result
    text_err = err.decode("utf-8", "replace")
    text_out = out.decode("utf-8", "replace")
    if timed_out:
        return "ran over its time limit (killed)"
    if code != 0 and elapsed > TIME_LIMIT_S:
        return f"exit {code} only after {elapsed:.1f} s of CPU: a refusal must come before any work"
    if code < 0:
        return f"killed by signal {-code}"
    if SANITIZER.search(text_err):
        return "sanitizer report:\n" + text_err[-3000:]
    if rss > RSS_LIMIT_KB:
        return f"max RSS {rss / 1024:.0f} MB over {RSS_LIMIT_KB / 1024:.0f} MB"
    json_mode = "--json" in argv
    given = {a.split("=", 1)[0] for a in argv if a.startswith("-")}
    if code == 0:
        # A path the user gave (--out inf) is echoed as given: it is not a number.
        scanned = text_out
        for i, x in enumerate(argv[:-1]):
            if opts.get(x) in ("FILE", "DIR", "IFACE", "V") and argv[i + 1]:
                scanned = scanned.replace(argv[i + 1], "<path>")
        if NON_FINITE.search(scanned):
            return "exit 0 with a non-finite number in stdout:\n" + text_out[:2000]
        if json_mode and command != "plant":
            try:
                doc = json.loads(text_out, parse_constant=lambda c: (_ for _ in ()).throw(ValueError(c)))
            except ValueError as e:
                return f"exit 0 with --json but stdout is not strict JSON ({e}):\n{text_out[:2000]}"
            if doc.get("status") != "ok":
                return "exit 0 with status " + str(doc.get("status"))
            # The JSON writer prints a non-finite number as null: a plan's own numbers must be there.
            if command == "plan":
                missing = [k for k in ("duration",) if not isinstance(doc.get(k), (int, float))]
                params = doc.get("params", {}) if isinstance(doc.get("params"), dict) else {}
                missing += ["params." + k for k, v in params.items() if not isinstance(v, (int, float))]
                if missing:
                    return "exit 0 with --json but no finite " + ", ".join(missing) + ":\n" + text_out[:2000]
        return None
    if code == 2:
        if json_mode:
            try:
                doc = json.loads(text_out)
            except ValueError:
                return "exit 2 with --json but stdout is not one JSON object:\n" + text_out[:2000]
            if doc.get("status") != "error" or not doc.get("message"):
                return "exit 2 JSON without status error and a message: " + text_out[:500]
            param = doc.get("parameter", "")
        else:
            if text_out:
                return "exit 2 with output on stdout:\n" + text_out[:500]
            lines = text_err.split("\n")
            if len(lines) != 2 or lines[1] != "":
                return "exit 2 without exactly one stderr line:\n" + text_err[:2000]
            m = re.match(r"settle: error: (\S+?): ", lines[0])
            if not m:
                return "exit 2 without 'settle: error: <option>: ...': " + lines[0][:300]
            param = m.group(1)
        if param != POSITIONAL.get(command) and param not in opts and param not in given and \
                param != "--" + command.replace(" ", "-"):
            return f"exit 2 names {param!r}, neither an option of settle {command} nor one given"
        return None
    if code == 1:
        if command.startswith("drive "):
            if json_mode:
                try:
                    doc = json.loads(text_out)
                except ValueError:
                    return "exit 1 with --json but stdout is not one JSON object:\n" + text_out[:2000]
                if doc.get("status") == "error" and doc.get("error") in DRIVE_FAILURE_CODES:
                    return None
            elif DRIVE_FAILURES.search(text_err) and text_err.count("\n") == 1:
                return None
            return "exit 1 that is not a documented drive failure:\n" + (text_err + text_out)[:2000]
        if command == "identify":
            if json_mode:
                try:
                    doc = json.loads(text_out)
                except ValueError:
                    return "exit 1 with --json but stdout is not one JSON object:\n" + text_out[:2000]
                if doc.get("status") == "error" and doc.get("error") in IDENTIFY_FAILURE_CODES:
                    return None
            elif IDENTIFY_FAILURES.search(text_err) and text_err.count("\n") == 1:
                return None
            return "exit 1 that is not a documented identify failure:\n" + (text_err + text_out)[:2000]
        if command in ("plant", "stream") and ("cannot open" in text_err or "cannot write" in text_err):
            return None
        if json_mode and text_out.count("\n") == 1:
            # A runtime failure with --json: the one error object every command prints (exit 1).
            try:
                doc = json.loads(text_out)
            except ValueError:
                doc = None
            if isinstance(doc, dict) and doc.get("status") == "error" and doc.get("error") in RUNTIME_FAILURE_CODES \
                    and doc.get("message"):
                return None
        if command == "stream" and ("outcome" in text_out):
            return None  # the move did not complete; the report says how
        if "cannot write" in text_err:
            return None
        return "exit 1 that is not a documented runtime failure:\n" + (text_err + text_out)[:2000]
    return f"exit status {code}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--settle", required=True)
    ap.add_argument("--seed", type=int, default=12)
    ap.add_argument("--count", type=int, default=1000)
    ap.add_argument("--sanitized", action="store_true",
                    help=f"a sanitized settle: a valid run (exit 0) may take {SANITIZED_LIMIT_S:.0f} s")
    ap.add_argument("--skip-if-missing", action="store_true",
                    help="exit 77 (ctest: skipped) when --settle does not exist (the sanitized build is optional)")
    ap.add_argument("--commands", default="", help="only these commands (comma-separated), for a quick local run")
    a = ap.parse_args()
    if a.skip_if_missing and not os.path.exists(a.settle):
        print(f"{a.settle} not built: skipped (cmake --preset host-clang-sanitize && cmake --build --preset "
              "host-clang-sanitize)")
        return 77
    a.settle = os.path.abspath(a.settle)
    top = subprocess.run([a.settle, "--help"], capture_output=True, text=True, timeout=30)
    listed = LISTED.findall(top.stdout.split("commands:", 1)[-1])
    undrawn = sorted(set(listed) - set(BASE) - set(NOT_DRAWN))
    if not listed or undrawn:
        sys.exit(f"settle --help lists {', '.join(undrawn) or 'no command'}: not drawn (BASE) nor said why not (NOT_DRAWN)")
    rng = random.Random(a.seed)
    opts = {c: help_options(a.settle, c) for c in BASE if not a.commands or c in a.commands.split(",")}
    only = set(a.commands.split(",")) if a.commands else set(BASE)
    commands = [c for c in BASE if c in only for _ in range(WEIGHT[c])]
    failures = []
    codes = {}
    slowest = (0.0, None)
    biggest = (0, None)
    with tempfile.TemporaryDirectory(prefix="settle-hostile-") as tmp:
        # The argument sets from BASE, then a fifth as many more from AXES_BASE on a generator of
        # their own (so that the sets from BASE stay those every earlier run of a seed drew).
        axes_commands = [c for c in commands if c in AXES_BASE]
        axes_rng = random.Random(a.seed * 7919 + 1)
        runs = [(k, rng, BASE) for k in range(a.count)]
        if axes_commands:
            runs += [(a.count + k, axes_rng, AXES_BASE) for k in range(a.count // 5)]
        for k, g, bases in runs:
            pool = commands if bases is BASE else axes_commands
            command = pool[k % len(pool)] if bases is BASE and k < len(pool) else g.choice(pool)
            args = list(bases[command])
            for _ in range(g.choice([1, 1, 2, 3])):
                args = mutate(g, command, opts[command], args, tmp)
            argv = [a.settle, *command.split()] + args
            result = run(argv, tmp, SANITIZED_LIMIT_S if a.sanitized else TIME_LIMIT_S)
            codes[(command, result[0])] = codes.get((command, result[0]), 0) + 1
            if result[2] > slowest[0]:
                slowest = (result[2], argv)
            if result[1] > biggest[0]:
                biggest = (result[1], argv)
            why = check(command, argv, opts[command], result)
            if why:
                failures.append((k, argv, why))
    summary = ", ".join(f"{c} exit {s}: {n}" for (c, s), n in sorted(codes.items()))
    print(f"{len(runs)} argument sets (seed {a.seed}; {len(runs) - a.count} from AXES_BASE); {summary}")
    short = lambda v: [x if len(x) < 60 else x[:20] + f"...({len(x)} chars)" for x in v[1:]][:40]
    print(f"slowest {slowest[0]:.2f} s: {short(slowest[1]) if slowest[1] else ''}")
    print(f"largest RSS {biggest[0] / 1024:.0f} MB: {short(biggest[1]) if biggest[1] else ''}")
    for k, argv, why in failures[:30]:
        print(f"\nFAIL #{k}: settle {' '.join(repr(x) for x in short(argv))}\n  {why}")
    if failures:
        print(f"\n{len(failures)} of {len(runs)} argument sets broke a rule")
        return 1
    print("every argument set ended cleanly")
    return 0


if __name__ == "__main__":
    sys.exit(main())
