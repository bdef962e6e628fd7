#!/usr/bin/env python3
"""End-to-end checks on a real SocketCAN bus (vcan0): `settle plant` and `settle stream` as two
processes, candump as a third. Run through tools/with-vcan (ctest -L vcan does). Each subcommand is
one ctest test; it exits non-zero with a message on the first failed check."""
import json, os, signal, subprocess, sys, tempfile, time

SETTLE = sys.argv[1]
TEST = sys.argv[2]
# The papers' scenarios, the same the demo streams (tools/paper_scenarios.py).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
import paper_scenarios  # noqa: E402

W000 = paper_scenarios.W000

# The drive and the loop tolerate a stalled user-mode-linux guest (see tools/demo-run).
PLANT_TOLERANT = ["--sync-loss-periods", "250"]
STREAM_TOLERANT = ["--heartbeat-ms", "2000", "--rt-priority", "50"]

# id -> (plant args, move args, axis vmax, out scale)
SCENARIOS = {row[0]: (row[2], row[3], row[4], row[5]) for row in paper_scenarios.scenarios()}


def fail(msg):
    print("FAIL:", msg)
    sys.exit(1)


def check(cond, msg):
    if not cond:
        fail(msg)
    print("ok:", msg)


class Bus:
    """candump on vcan0 for the duration of a with-block."""

    def __init__(self, d):
        self.path = os.path.join(d, "bus.log")

    def __enter__(self):
        self.f = open(self.path, "w")
        self.p = subprocess.Popen(["candump", "-L", "vcan0"], stdout=self.f)
        time.sleep(0.1)
        return self

    def __exit__(self, *a):
        time.sleep(0.1)
        self.p.terminate()
        self.p.wait()
        self.f.close()

    def frames(self, with_time=False):
        out = []
        for line in open(self.path):
            parts = line.split()
            if len(parts) == 3 and "#" in parts[2]:
                cid, data = parts[2].split("#", 1)
                t = float(parts[0].strip("()"))
                out.append((int(cid, 16), data, t) if with_time else (int(cid, 16), data))
        return out


def start_plant(d, tag, plant_args, extra=()):
    log = os.path.join(d, f"plant-{tag}.csv")
    js = open(os.path.join(d, f"plant-{tag}.json"), "w")
    p = subprocess.Popen([SETTLE, "plant", "--bus", "vcan0", *plant_args, "--log", log, "--json", *extra],
                         stdout=js, stderr=subprocess.DEVNULL)
    time.sleep(0.3)
    return p, log, js


def stop_plant(p, js, d, tag):
    p.send_signal(signal.SIGTERM)
    p.wait(timeout=30)
    js.close()
    return json.load(open(os.path.join(d, f"plant-{tag}.json")))


def stream(d, tag, plant_args, move_args, vmax, extra=(), timeout=120):
    fb = os.path.join(d, f"feedback-{tag}.csv")
    r = subprocess.run([SETTLE, "stream", "--bus", "vcan0", *plant_args, *move_args, "--axis-vmax", str(vmax),
                        "--feedback-log", fb, "--json", *STREAM_TOLERANT, *extra],
                       capture_output=True, text=True, timeout=timeout)
    try:
        return r.returncode, json.loads(r.stdout), fb
    except json.JSONDecodeError:
        fail(f"stream printed no JSON (exit {r.returncode}): {r.stdout} {r.stderr}")


def read_csv(path):
    lines = open(path).read().split("\n")
    head = lines[0].split(",")
    return [dict(zip(head, map(float, l.split(",")))) for l in lines[1:] if l]


def scenario(d, tag):
    plant_args, move_args, vmax, out_scale = SCENARIOS[tag]
    p, plog, js = start_plant(d, tag, plant_args, PLANT_TOLERANT)
    rc, r, fb = stream(d, tag, plant_args, move_args, vmax)
    pj = stop_plant(p, js, d, tag)
    check(rc == 0 and r["outcome"] == "completed",
          f"{tag}: session completed ({r['outcome']}; drive {r.get('drive_state')} {r.get('drive_failure', '')})")
    check(r["aligned"], f"{tag}: the CAN feedback matches the offline replay period by period")
    tol = 1e-6 * out_scale
    check(r["agreement"] <= tol, f"{tag}: residual from CAN {r['residual_can']:.6e} agrees with offline "
                                 f"{r['residual_offline']:.6e} within 1e-6 of the distance ({r['agreement']:.1e} <= {tol:.1e})")
    check(r["frames_lost"] == 0 and pj["rx_overflow_drops"] == 0, f"{tag}: no frame lost on either side")
    # Every setpoint sent was applied exactly once, in order: the drive's own log of applied
    # targets contains the commanded sequence contiguously, exactly once.
    cmd = [int(row["commanded"]) for row in read_csv(fb) if row["period"] >= 0]
    move = cmd[: cmd.index(cmd[-1]) + 1]
    applied = [int(row["target"]) for row in read_csv(plog) if row["following"] == 1]
    hits = [i for i in range(len(applied) - len(move) + 1) if applied[i:i + len(move)] == move]
    check(len(hits) == 1, f"{tag}: the drive applied the {len(move)} setpoints of the move once, in order")
    return r


def main():
    with tempfile.TemporaryDirectory(prefix="settle-e2e-") as d:
        if TEST in SCENARIOS:
            with Bus(d):
                scenario(d, TEST)
        elif TEST == "ten-thousand-ticks":
            plant_args, move_args, vmax, _ = SCENARIOS["000-scurve-0.8"]
            p, plog, js = start_plant(d, "long", plant_args, PLANT_TOLERANT)
            rc, r, fb = stream(d, "long", plant_args, move_args, vmax, ["--settle-time", "9.8"])
            pj = stop_plant(p, js, d, "long")
            check(r["ticks"] >= 10000, f"{r['ticks']} ticks at 1 kHz")
            check(r["aligned"] and rc == 0, "every setpoint applied once, in order, feedback complete")
            check(r["frames_lost"] == 0 and pj["rx_overflow_drops"] == 0 and pj["rpdos_missing"] == 0,
                  f"zero frames lost (loop drops {r['frames_lost']}, drive drops {pj['rx_overflow_drops']}, RPDOs missing {pj['rpdos_missing']})")
            print("throughput: %.0f frames/s sent, %.0f received by the loop" % (r["frames_sent"] / (r["ticks"] / 1000), r["frames_received"] / (r["ticks"] / 1000)))
        elif TEST == "plant-dies-mid-move":
            plant_args = ["--plant", "beam"]
            move = ["--profile", "scurve", "--distance", "0.5", "--time", "4", "--omega", f"{W000}"]
            p, plog, js = start_plant(d, "dies", plant_args, PLANT_TOLERANT)
            with Bus(d) as bus:
                s = subprocess.Popen([SETTLE, "stream", "--bus", "vcan0", *plant_args, *move, "--axis-vmax", "1",
                                      "--json", "--heartbeat-ms", "400"], stdout=subprocess.PIPE, text=True)
                time.sleep(2.0)
                p.kill()  # the drive process dies without a word
                p.wait()
                t_kill = time.time()
                out, _ = s.communicate(timeout=60)
            r = json.loads(out)
            check(r["outcome"] == "drive_lost" and s.returncode != 0, f"the loop reports the lost drive ({r['outcome']})")
            check(r["heartbeat_losses"] == 1 and r["moves_aborted"] == 1, "heartbeat loss detected, move abandoned")
            # No setpoint left the loop once the heartbeat was declared lost: the last RPDO is no
            # later than the last heartbeat plus the 400 ms timeout (plus a tick and a margin for
            # the guest's timer).
            frames = bus.frames(with_time=True)
            last_rpdo = max(t for cid, _, t in frames if cid == 0x201)
            last_hb = max(t for cid, _, t in frames if cid == 0x701)
            check(last_rpdo - last_hb <= 0.4 + 0.05,
                  f"no setpoints streamed once the heartbeat was lost ({last_rpdo - last_hb:.3f} s after the last heartbeat)")
        elif TEST == "loop-dies-mid-move":
            plant_args = ["--plant", "beam"]
            move = ["--profile", "scurve", "--distance", "0.5", "--time", "4", "--omega", f"{W000}"]
            p, plog, js = start_plant(d, "orphan", plant_args, ["--sync-loss-periods", "20"])
            with Bus(d) as bus:
                s = subprocess.Popen([SETTLE, "stream", "--bus", "vcan0", *plant_args, *move, "--axis-vmax", "1",
                                      "--json", *STREAM_TOLERANT], stdout=subprocess.DEVNULL)
                time.sleep(2.0)
                s.kill()  # the servo loop dies mid-move: SYNCs stop
                s.wait()
                time.sleep(1.0)
                pj = stop_plant(p, js, d, "orphan")
            check(pj["emcy_sent"] >= 1, f"the drive sent an EMCY ({pj['emcy_sent']})")
            check(pj["state"] != "operation enabled", f"the drive left operation enabled ({pj['state']})")
            emcy = [data for cid, data in bus.frames() if cid == 0x81]
            check(len(emcy) >= 1, f"EMCY on the bus: {emcy[:2]}")
        elif TEST == "refused-before-any-frame":
            with Bus(d) as bus:
                r = subprocess.run([SETTLE, "stream", "--bus", "vcan0", "--plant", "beam", "--profile", "scurve",
                                    "--distance", "0.05", "--time", "0.2", "--omega", f"{W000}", "--amax", "1", "--json"],
                                   capture_output=True, text=True)
            j = json.loads(r.stdout)
            check(r.returncode == 2 and j["error"] == "acceleration_limit_exceeded", f"refused: {j['error']}")
            check(len(bus.frames()) == 0, "not a single frame reached the bus")
        elif TEST == "no-drive-says-why":
            with Bus(d) as bus:
                r = subprocess.run([SETTLE, "stream", "--bus", "vcan0", "--plant", "beam", "--profile", "scurve",
                                    "--distance", "0.05", "--time", "0.2", "--omega", f"{W000}", "--sdo-timeout-ms",
                                    "300", "--json"], capture_output=True, text=True, timeout=60)
            j = json.loads(r.stdout)
            check(r.returncode != 0 and j["outcome"] == "enable_failed", f"nobody answers: {j['outcome']}")
            check(j["drive_state"] == "failed" and "timed out" in j["drive_failure"],
                  f"and the loop says why: {j['drive_state']}: {j['drive_failure']}")
            check(not any(cid == 0x201 for cid, _ in bus.frames()), "no setpoint was sent to a drive never enabled")
        else:
            fail("unknown test " + TEST)


main()
