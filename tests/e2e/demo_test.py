#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""`settle demo` against its own scenario list (`settle demo --list --json`): first, per paper (named
by its title) and move time, the method's and the baseline's residual and PRV over CAN, the ratio and
the verdict, each number its run's (their JSON files) and each method below its baseline; then the
transport table, one row per scenario in order, each run completed and aligned with its offline
replay, every column explained; on a SocketCAN bus each row's bus log holds every frame its counters
count, and bus.log is their sum. The commissioning, then double, float and fixed on every scenario,
each within 1 % or one load count of double. No line over 100 columns. A plot per scenario when
gnuplot is there.

  demo_test.py SETTLE loopback|IFACE      (IFACE: run through tools/with-vcan)
"""
import json, os, re, shutil, subprocess, sys, tempfile

SETTLE, BUS = sys.argv[1], sys.argv[2]


def fail(msg):
    print("FAIL:", msg)
    sys.exit(1)


def check(cond, msg):
    if not cond:
        fail(msg)
    print("ok:", msg)


def option(args, name):
    return args[args.index(name) + 1]


def table(lines, header_start):
    """The rows of the table whose header line starts with header_start: up to the first blank line."""
    at = next((i for i, l in enumerate(lines) if l.startswith(header_start)), None)
    if at is None:
        fail(f"no table headed {header_start!r} in:\n" + "\n".join(lines))
    rows = []
    for l in lines[at + 1:]:
        if not l.strip():
            break
        rows.append(l)
    return rows


def main():
    listing = subprocess.run([SETTLE, "demo", "--list", "--json"], capture_output=True, text=True, timeout=60)
    check(listing.returncode == 0, "settle demo --list --json")
    scenarios = json.loads(listing.stdout)["scenarios"]
    commissioning = json.loads(listing.stdout)["commissioning"]
    check(len(scenarios) >= 8, f"{len(scenarios)} scenarios listed")
    socketcan = BUS != "loopback"
    with tempfile.TemporaryDirectory(prefix="settle-demo-") as out:
        r = subprocess.run([SETTLE, "demo", "--bus", BUS, "--out", out], capture_output=True, text=True, timeout=1100)
        print(r.stdout)
        check(r.returncode == 0, f"settle demo --bus {BUS} exited {r.returncode}: {r.stderr[-2000:]}")
        lines = r.stdout.splitlines()
        check(any(l.startswith("bus: " + ("vcan0" if socketcan else "loopback")) for l in lines),
              "the report says which bus was used")
        check(all(len(l) <= 100 for l in lines), "no line of the report is over 100 columns")
        results_end = next(i for i, l in enumerate(lines) if l.startswith("Transport and timing"))
        results = lines[:results_end]
        runs = {s["id"]: json.load(open(os.path.join(out, f"stream-{s['id']}.json"))) for s in scenarios}
        # The papers' results first: a row per paper and move time, its method's residual and PRV
        # over CAN against its baseline's, the ratio, and "less?" (the demo would have exited 1 on a no).
        listed = json.loads(listing.stdout)["papers"]
        methods = [s for s in scenarios if s["role"] == "method"]
        check(len(methods) == len(scenarios) // 2 and {s["paper"] for s in scenarios} == set(range(len(listed))),
              "every paper has its methods, each with its baseline")
        for m in methods:
            title = listed[m["paper"]]["title"]
            at = next((i for i, l in enumerate(results) if l == title), None)
            check(at is not None, f"{m['id']}: its paper is named: {title}")
            b = next(s for s in scenarios if s["role"] == "baseline" and s["paper"] == m["paper"] and
                     s["when"] == m["when"])
            row = next((l for l in results[at:] if l.startswith("  " + m["when"] + " ")), None)
            check(row is not None, f"{m['id']}: a row for {m['when']!r}")
            cells = row[len("  " + m["when"]):].split()
            jm, jb = runs[m["id"]], runs[b["id"]]
            for run, j in ((m, jm), (b, jb)):
                check(j["status"] == "ok" and j["aligned"], f"{run['id']}: completed, CAN feedback aligned with the replay")
            ratio = jb["residual_can"] / jm["residual_can"]
            want = [f"{jm['residual_can']:.3e}", m["unit"], f"{jm['prv_can_percent']:.3g}", "%",
                    f"{jb['residual_can']:.3e}", b["unit"], f"{jb['prv_can_percent']:.3g}", "%",
                    (f"{ratio:.0f}" if ratio >= 10 else f"{ratio:.2g}") + "×", "yes"]
            check(cells == want and jm["residual_can"] < jb["residual_can"],
                  f"{m['id']} against {b['id']}: {' '.join(cells)} are their runs' residuals, the method's less")
        # Then the transport table, one row per run in the list's order, every number its run's.
        rows = table(lines, "run                             sent")
        check(len(rows) == len(scenarios), f"the transport table has one row per scenario ({len(rows)} rows)")
        logged_total = 0
        for row, s in zip(rows, scenarios):
            j = runs[s["id"]]
            check(row.startswith(s["label"] + " "), f"{s['id']}: row '{s['label']}' in the list's order")
            sent, recv, logged, lost, late, overruns, skipped, agreement = row[len(s["label"]):].split()
            check([sent, recv, late, overruns, skipped, agreement] ==
                  [str(j["frames_sent"]), str(j["frames_received"]), str(j["feedback_late_ticks"]), str(j["overruns"]),
                   str(j["skipped_periods"]), f"{j['agreement']:.1e}"],
                  f"{s['id']}: frames {sent}/{recv}, late {late}, overruns {overruns} ({skipped} periods) are its run's")
            if socketcan:
                lines_in_log = sum(1 for _ in open(os.path.join(out, f"stream-{s['id']}.log")))
                check(logged == str(lines_in_log) and lines_in_log == j["frames_sent"] + j["frames_received"],
                      f"{s['id']}: its bus log holds every frame it counted ({lines_in_log})")
                logged_total += lines_in_log
                plant = json.load(open(os.path.join(out, f"plant-{s['id']}.json")))
                check(plant["frames_received"] == j["frames_sent"] + 1,
                      f"{s['id']}: the drive process took every frame the loop sent, and the barrier")
                check(lost == str(j["frames_lost"] + plant["rx_overflow_drops"]), f"{s['id']}: {lost} frames lost")
            else:
                check(logged == "-" and lost == str(j["frames_lost"]), f"{s['id']}: no bus log counted on loopback")
            if shutil.which("gnuplot"):
                check(os.path.getsize(os.path.join(out, f"{s['id']}.png")) > 0, f"{s['id']}: plot written")
        for column in ("sent, received:", "logged:", "lost:", "late:", "overruns:", "CAN - replay:"):
            check(any(l.startswith(column) for l in lines), f"the column '{column}' is explained")
        if socketcan:
            bus_lines = sum(1 for _ in open(os.path.join(out, "bus.log")))
            check(bus_lines == logged_total and any(l.startswith(f"bus.log: {bus_lines} frames") and "(complete)" in l
                                                     for l in lines), f"bus.log: {bus_lines} frames, complete")
        # Float and fixed against double: every number from the runs' JSON, every row a pass by the
        # criterion computed here (within 1 % or within one load count).
        scalar_rows = table(lines, "run                              double |")
        check(len(scalar_rows) == len(scenarios), f"the evaluation table has one row per scenario")
        for row, s in zip(scalar_rows, scenarios):
            check(row.startswith(s["label"] + " "), f"{s['id']}: evaluation row in the list's order")
            dbl, bar1, *rest = row[len(s["label"]):].split()
            fl, fx = rest[:4], rest[5:]
            jd = json.load(open(os.path.join(out, f"scalar-double-{s['id']}.json")))
            check(dbl == f"{jd['residual_can']:.4e}", f"{s['id']}: double's residual {dbl}")
            for name, cells in (("float", fl), ("fixed", fx)):
                j = json.load(open(os.path.join(out, f"scalar-{name}-{s['id']}.json")))
                pct, counts = j["residual_vs_double_percent"], j["residual_vs_double_load_counts"]
                agrees = pct <= 1.0 or counts <= 1.0
                check(j["status"] == "ok" and j["aligned"] and agrees and
                      cells == [str(j["setpoints_vs_double_max_counts"]), f"{pct:.3g}", f"{counts:.2g}", "yes"],
                      f"{s['id']} {name}: {' '.join(cells)} (setpoint counts, residual %, load counts) within the bound")
        check(f"float and fixed agree with double on {2 * len(scenarios)} of {2 * len(scenarios)} runs" in lines,
              "the agreement count covers float and fixed on every scenario")
        # The commissioning scenario: one row per true mode, identified within the tolerances (the
        # numbers its identify run reported), the tuned plan streamed with its PRV from the CAN
        # feedback within the bound, and the verdict.
        cid = commissioning["id"]
        ident = json.load(open(os.path.join(out, f"identify-{cid}.json")))
        tuned = json.load(open(os.path.join(out, f"tune-{cid}.json")))
        streamed = json.load(open(os.path.join(out, f"stream-{cid}.json")))
        mode_rows = [l for l in table(lines, "mode  ") if re.match(r"\d+ ", l)]
        check(len(mode_rows) == len(commissioning["modes"]) == len(ident["modes"]),
              f"commissioning: one row per true mode ({len(mode_rows)})")
        for row, truth, m in zip(mode_rows, commissioning["modes"], ident["modes"]):
            cells = row.split()
            check(cells[1] == f"{truth['omega']:.4f}" and cells[2] == f"{m['omega']:.4f}" and cells[-1] == "yes" and
                  abs(m["omega"] / truth["omega"] - 1) <= commissioning["omega_tolerance"] and
                  abs(m["zeta"] - truth["zeta"]) <= commissioning["zeta_tolerance"],
                  f"commissioning: {row.strip()}")
        check(streamed["status"] == "ok" and streamed["move_time"] == tuned["duration"] and
              streamed["prv_can_percent"] <= commissioning["prv_max_percent"] and
              f"CAN feedback {streamed['prv_can_percent']:.4f} %" in " ".join(lines),
              f"commissioning: the tuned plan ({tuned['candidate']['name']}, {tuned['duration']:.4f} s) streamed, "
              f"PRV from CAN {streamed['prv_can_percent']:.4f} %")
        check("commissioning: ok" in lines, "commissioning: ok")
    if not socketcan:
        ids = [s["id"] for s in scenarios]
        text = subprocess.run([SETTLE, "demo", "--list"], capture_output=True, text=True, timeout=60)
        check(text.returncode == 0 and all(f"\n{i} " in text.stdout for i in ids), "settle demo --list names every id")
        with tempfile.TemporaryDirectory(prefix="settle-demo-") as out:
            r = subprocess.run([SETTLE, "demo", "--bus", "loopback", "--out", out, "--json"], capture_output=True,
                               text=True, timeout=300)
            j = json.loads(r.stdout)
            check(r.returncode == 0 and j["status"] == "ok" and [x["id"] for x in j["runs"]] == ids and
                  all(x["ok"] and x["stream"]["aligned"] for x in j["runs"]) and [x["id"] for x in j["scalars"]] == ids
                  and all(x["float_agrees"] and x["fixed_agrees"] for x in j["scalars"])
                  and j["commissioning"]["ok"] and len(j["commissioning"]["modes"]) == len(commissioning["modes"]),
                  "settle demo --json: one run and one set of evaluations per scenario, in order, each ok; the "
                  "commissioning ok")
            by_id = {x["id"]: x["stream"] for x in j["runs"]}
            methods = [s for s in scenarios if s["role"] == "method"]
            check([(v["method"], v["when"]) for v in j["verdicts"]] == [(s["id"], s["when"]) for s in methods] and
                  all(v["less"] and by_id[v["method"]]["residual_can"] < by_id[v["baseline"]]["residual_can"] and
                      abs(v["ratio"] - by_id[v["baseline"]]["residual_can"] / by_id[v["method"]]["residual_can"])
                      <= 1e-9 * v["ratio"] for v in j["verdicts"]) and len(j["papers"]) == 3,
                  "settle demo --json: a verdict per method, each less than its baseline, with the ratio")
            # A bus that cannot be opened is refused before any process starts.
            r = subprocess.run([SETTLE, "demo", "--bus", "settle-no-such-can0", "--out", out + "/none"],
                               capture_output=True, text=True, timeout=60)
            check(r.returncode == 1 and "cannot open settle-no-such-can0" in r.stderr and
                  not os.path.exists(out + "/none/stream-" + ids[0] + ".json"),
                  f"an interface that does not exist: exit 1, nothing run ({r.stderr.strip()})")
        r = subprocess.run([SETTLE, "demo", "--bus", ""], capture_output=True, text=True, timeout=60)
        check(r.returncode == 2 and r.stderr.startswith("settle: error: --bus:"), "an empty --bus: exit 2 naming it")
    print("the demo's tables match its scenario list")


main()
