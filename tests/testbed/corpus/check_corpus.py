#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""The corpus, file by file (the table below): `settle drive info`, `settle drive config` and
`settle stream --bus loopback` against the drive simulated from the same file, each checked for
its exit status, the warnings it prints (exactly these, naming section and key) and the outcome:
configured (and called verified only without warnings), streamed to completion, the rest not
measured (no file marks a load position) unless stated. Usage: check_corpus.py --settle PATH"""
import argparse
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))

# file: (node, mapping, [warnings as "[section] key"]); every file streams to completion.
EXPECTED = {
    "01_python_export_hexbool.eds": (1, "dynamic", []),
    "02_big_manufacturer_section.eds": (1, "static (read and checked)", []),
    "03_crlf_lowercase.eds": (1, "dynamic", []),
    "04_no_1006.eds": (1, "static (read and checked)", []),
    "05_no_60c2.eds": (1, "dynamic", []),
    "06_commissioned.dcf": (3, "static (read and checked)", []),
    "07_long_lines_subnumber.eds": (1, "static (read and checked)", ["[1018] SubNumber"]),
    "08_loose_lists.eds": (1, "static (read and checked)",
                           ["[OptionalObjects] SupportedObjects", "[DeviceInfo] NrOfRXPDO"]),
    "09_record_and_compact.eds": (1, "dynamic", []),
    "10_identity_mismatch.eds": (1, "static (read and checked)", ["[DeviceInfo] ProductNumber"]),
}


def run(settle, args):
    p = subprocess.run([settle] + args, capture_output=True, text=True, timeout=600)
    return p.returncode, p.stdout, p.stderr


def warnings_of(stderr):
    return [line for line in stderr.splitlines() if "--eds warning:" in line]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--settle", required=True)
    settle = ap.parse_args().settle
    failures = []
    files = sorted(f for f in os.listdir(HERE) if f.endswith((".eds", ".dcf")))
    if sorted(EXPECTED) != files:
        failures.append("the table and the folder differ: %s vs %s" % (sorted(EXPECTED), files))
    for name in sorted(EXPECTED):
        node, mapping, warned = EXPECTED[name]
        path = os.path.join(HERE, name)
        common = ["--bus", "loopback", "--node", str(node), "--eds", path]

        def check(what, ok, detail=""):
            if not ok:
                failures.append("%s: %s %s" % (name, what, detail[:2000]))

        rc, out, err = run(settle, ["drive", "info"] + common + ["--json"])
        check("drive info exits 0", rc == 0, err)
        got = warnings_of(err)
        check("drive info warns %d times" % len(warned), len(got) == len(warned), "\n".join(got))
        for w in warned:
            check("drive info warns about " + w, any(w in line for line in got), "\n".join(got))
        if rc == 0:
            check("drive info lists its warnings in JSON", len(json.loads(out)["eds_warnings"]) == len(warned), out)
        rc, out, err = run(settle, ["drive", "info"] + common + ["--strict"])
        check("--strict refuses exactly the warned files", (rc == 2) == bool(warned), err)

        rc, out, err = run(settle, ["drive", "config"] + common + ["--json"])
        check("drive config exits 0", rc == 0, err)
        if rc == 0:
            j = json.loads(out)
            check("drive config maps " + mapping, j["pdo_mapping"] == mapping, j["pdo_mapping"])
            check("drive config verified only without warnings", j["verified"] == (not warned), out)
            needed = [o for o in j["objects"] if o["needed"]]
            check("every needed object found and used", all(o["found"] and o["use"] for o in needed), out)

        rc, out, err = run(settle, ["stream"] + common + ["--profile", "poly345", "--distance", "0.01", "--time",
                                                         "0.5", "--json"])
        check("stream exits 0", rc == 0, err)
        if rc == 0:
            j = json.loads(out)
            check("stream completes", j.get("outcome") == "completed", out)
            check("the rest is not measured (no load position marked)", j.get("rest_measured") is False, out)
            check("the residual is null, not a number from zeros", j.get("residual_can") is None, out)
        print("%-34s checked" % name)
    for f in failures:
        print("FAIL " + f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
