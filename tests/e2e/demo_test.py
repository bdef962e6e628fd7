#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""`settle demo` against its own scenario list (`settle demo --list --json`): first, per paper (named
by its title) and move time, the method's and the baseline's residual and PRV over CAN, the ratio and
the verdict, each number its run's (their JSON files) and each method below its baseline; then the
transport table, one row per scenario in order, each run completed and aligned with its offline
replay, every column explained; on a SocketCAN bus each row's bus log holds every frame its counters
count, and bus.log is what the bus saw (check_bus_log). Every bus.log is read by Wireshark's CANopen
dissector. The commissioning, then double, float and fixed on every scenario, each within 1 % or one
load count of double. No line over 100 columns. A plot per scenario when gnuplot is there.

  demo_test.py SETTLE loopback|IFACE      (IFACE: run through tools/with-vcan)
"""
import json, os, re, shutil, subprocess, sys, tempfile

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
import canopen_decode  # noqa: E402

SETTLE, BUS = sys.argv[1], sys.argv[2]
MASTER_TYPES, NODE_TYPES = canopen_decode.MASTER_TYPES, canopen_decode.NODE_TYPES
BARRIER = (0x601, "4018100400000000")  # the demo's barrier: an SDO upload of 0x1018:4


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


def check_bus_log(out, lines, sessions):
    """bus.log, read by Wireshark's CANopen dissector: no frame malformed or in error, every frame
    CANopen. On SocketCAN (sessions: (name, its drive's JSON) in the order they ran) it is what the
    bus saw: the capture's line says it is complete (nothing dropped, nothing out of order), its
    timestamps never step back, and each session (from its drive's boot-up) holds every frame its
    drive process sent and took as the drive counted them, the SYNCs it counted, its EMCYs and the
    demo's barrier SDO and its answer."""
    path = os.path.join(out, "bus.log")
    d = canopen_decode.decode(path)
    check(not d.errors and d.count("other") == 0,
          f"bus.log: tshark's CANopen dissector reads its {d.frames} frames ({d.summary()}), none malformed or in "
          f"error {d.errors[:5]}, every one CANopen ({d.count('other')} not)")
    if sessions is None:
        return
    said = next((l for l in lines if l.startswith("bus.log: ")), "")
    m = re.match(r"bus\.log: (\d+) frames captured on \S+, [\d.]+ s, (\d+) kernel drops, (\d+) out of time "
                 r"order \(complete\)$", said)
    check(m is not None and int(m.group(1)) == d.frames and m.group(2) == "0" and m.group(3) == "0",
          f"the demo says bus.log is complete, {d.frames} frames, none dropped or out of order: {said!r}")
    frames = canopen_decode.read_candump(path)
    stamps = [sec * 1_000_000 + usec for sec, usec, _, _, _ in frames]
    back = sum(1 for a, b in zip(stamps, stamps[1:]) if b < a)
    check(back == 0, f"bus.log: its timestamps never step back ({back} lines do)")
    boots = [i for i, (_, _, cid, _, data) in enumerate(frames) if cid == 0x701 and data == b"\0"]
    check(len(boots) == len(sessions), f"bus.log: {len(boots)} drive boot-ups, one per session ({len(sessions)})")
    for k, ((name, plant_json), start) in enumerate(zip(sessions, boots)):
        end = boots[k + 1] if k + 1 < len(boots) else len(frames)
        pj = json.load(open(os.path.join(out, plant_json)))
        types = d.types[start:end]
        n = {t: types.count(t) for t in set(types)}
        master = sum(n.get(t, 0) for t in MASTER_TYPES)
        node = sum(n.get(t, 0) for t in NODE_TYPES)
        check(master == pj["frames_received"] and node == pj["frames_sent"] and n.get("sync", 0) == pj["syncs"] and
              n.get("emcy", 0) == pj["emcy_sent"],
              f"bus.log, {name}: the drive process's {pj['frames_sent']} frames sent and {pj['frames_received']} "
              f"taken, {pj['syncs']} SYNCs, {pj['emcy_sent']} EMCYs are all there (the dissector finds {master} "
              f"to the drive and {node} from it: {', '.join(f'{t} {c}' for t, c in sorted(n.items()))})")
        sdo = [(cid, data.hex().upper()) for _, _, cid, _, data in frames[start:end] if cid in (0x601, 0x581)]
        at = max((i for i, f in enumerate(sdo) if f == BARRIER), default=None)
        check(at is not None and any(cid == 0x581 and data[2:8] == "181004" for cid, data in sdo[at + 1:]),
              f"bus.log, {name}: the demo's barrier SDO and the drive's answer after it ({sdo[-3:]})")


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
        sessions = [(s["id"], f"plant-{s['id']}.json") for s in scenarios]
        sessions += [(f"{commissioning['id']} ({step})", f"plant-{commissioning['id']}-{step}.json")
                     for step in ("identify", "stream")]
        check_bus_log(out, lines, sessions if socketcan else None)
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
        check(streamed["status"] == "ok" and streamed["duration"] == tuned["duration"] and
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
