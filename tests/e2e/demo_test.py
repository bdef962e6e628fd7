#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""`settle demo` against its own scenario list (`settle demo --list --json`): its first table has one
row per scenario, in order, with the scenario's label and profile, each run completed and aligned
with its offline replay, and the residuals it prints are the ones its runs reported (their JSON
files); on a SocketCAN bus each row's bus log holds every frame its counters count, and bus.log is
what the bus saw (check_bus_log). Every bus.log is read by Wireshark's CANopen dissector. The second table compares double, float and fixed on every scenario. A plot per
scenario when gnuplot is there.

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
    m = re.match(r"bus\.log: (\d+) frames captured on \S+, [\d.]+ s, (\d+) dropped by the kernel, (\d+) out of time "
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
        check(any(l.startswith("Settle demo: bus " + ("vcan0" if socketcan else "loopback")) for l in lines),
              "the table says which bus was used")
        rows = table(lines, "scenario            profile         T (s)")
        check(len(rows) == len(scenarios), f"one row per scenario ({len(rows)} rows)")
        for row, s in zip(rows, scenarios):
            cells = row.split()
            label_words = len(s["label"].split())
            label, profile = " ".join(cells[:label_words]), cells[label_words]
            check(label == s["label"] and profile == option(s["move"], "--profile"),
                  f"{s['id']}: row '{label} {profile}' in the list's order")
            check("<-" not in row and "no result" not in row, f"{s['id']}: no failure marked")
            j = json.load(open(os.path.join(out, f"stream-{s['id']}.json")))
            check(j["status"] == "ok" and j["aligned"], f"{s['id']}: completed, CAN feedback aligned with the replay")
            nums = cells[label_words + 1:]
            sent, recv, logged = nums[1], nums[2], nums[3]
            check(sent == str(j["frames_sent"]) and recv == str(j["frames_received"]) and
                  nums[7] == f"{j['residual_can']:.3e}" and nums[9] == f"{j['residual_offline']:.3e}",
                  f"{s['id']}: frames {sent}/{recv} and residual {nums[7]} are its run's")
            if socketcan:
                lines_in_log = sum(1 for _ in open(os.path.join(out, f"stream-{s['id']}.log")))
                check(logged == str(lines_in_log) and lines_in_log == j["frames_sent"] + j["frames_received"],
                      f"{s['id']}: its bus log holds every frame it counted ({lines_in_log})")
                plant = json.load(open(os.path.join(out, f"plant-{s['id']}.json")))
                check(plant["frames_received"] == j["frames_sent"] + 1,
                      f"{s['id']}: the drive process took every frame the loop sent, and the barrier")
            else:
                check(logged == "-", f"{s['id']}: no bus log counted on loopback")
            if shutil.which("gnuplot"):
                check(os.path.getsize(os.path.join(out, f"{s['id']}.png")) > 0, f"{s['id']}: plot written")
        sessions = [(s["id"], f"plant-{s['id']}.json") for s in scenarios]
        sessions += [(f"{commissioning['id']} ({step})", f"plant-{commissioning['id']}-{step}.json")
                     for step in ("identify", "stream")]
        check_bus_log(out, lines, sessions if socketcan else None)
        scalar_rows = table(lines, "scenario            profile        residual dbl")
        check(len(scalar_rows) == len(scenarios), f"the evaluation table has one row per scenario")
        for row, s in zip(scalar_rows, scenarios):
            check(row.startswith(s["label"]) and "no result" not in row and "not aligned" not in row,
                  f"{s['id']}: double, float and fixed ran and aligned")
        m = next((re.match(r"float and fixed agree with double on (\d+) of (\d+) runs", l) for l in lines
                  if l.startswith("float and fixed agree")), None)
        check(m is not None and int(m.group(2)) == 2 * len(scenarios) and int(m.group(1)) <= int(m.group(2)),
              "the agreement count covers float and fixed on every scenario")
        # The commissioning scenario: one row per true mode, identified within the tolerances (the
        # numbers its identify run reported), the tuned plan streamed with its PRV from the CAN
        # feedback within the bound, and the verdict.
        cid = commissioning["id"]
        ident = json.load(open(os.path.join(out, f"identify-{cid}.json")))
        tuned = json.load(open(os.path.join(out, f"tune-{cid}.json")))
        streamed = json.load(open(os.path.join(out, f"stream-{cid}.json")))
        mode_rows = table(lines, "mode  ")
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
              any(l.startswith("streamed ") and f"{streamed['prv_can_percent']:.4f} %" in l for l in lines),
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
                  and j["commissioning"]["ok"] and len(j["commissioning"]["modes"]) == len(commissioning["modes"]),
                  "settle demo --json: one run and one set of evaluations per scenario, in order, each ok; the "
                  "commissioning ok")
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
