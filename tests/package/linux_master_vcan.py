#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""examples/linux_master (built against the installed package) streams its move over vcan0 to a
`settle plant` process. Readiness by frames: the plant is ready once its heartbeat (0x701, every
100 ms) shows on the bus. Run through tools/with-vcan (ctest -L vcan does).
usage: linux_master_vcan.py <settle> <linux_master>"""
import select, subprocess, sys, time

SETTLE, MASTER = sys.argv[1], sys.argv[2]


def fail(msg):
    print("FAIL:", msg)
    sys.exit(1)


def wait_for_heartbeat(candump, limit_s=120):
    """Reads candump -L lines until node 1's heartbeat; fails after limit_s without one."""
    end = time.monotonic() + limit_s
    while time.monotonic() < end:
        ready, _, _ = select.select([candump.stdout], [], [], 1.0)
        if ready:
            line = candump.stdout.readline()
            if not line:
                fail("candump ended before the plant's heartbeat")
            if " 701#" in line:
                return
    fail(f"no heartbeat from settle plant within {limit_s} s")


def stop(candump):
    if candump.poll() is None:
        candump.kill()
        candump.wait(timeout=30)
    candump.stdout.close()


candump = subprocess.Popen(["candump", "-L", "vcan0"], stdout=subprocess.PIPE, text=True)
plant = subprocess.Popen([SETTLE, "plant", "--bus", "vcan0", "--sync-loss-periods", "250"],
                         stdout=subprocess.DEVNULL)
try:
    wait_for_heartbeat(candump)
    stop(candump)  # seen what it had to show; unread, its pipe would fill and block it
    r = subprocess.run([MASTER, "vcan0"], capture_output=True, text=True, timeout=240)
    print(r.stdout, r.stderr, end="")
    if r.returncode != 0 or "session completed" not in r.stdout:
        fail(f"linux_master did not complete its session (exit {r.returncode})")
    # Target and final position both 50000 counts (0.05 m at 1 count per µm).
    if "drive at 50000 counts (target 50000)" not in r.stdout:
        fail("the drive did not end on the move's target")
    print("ok: linux_master streamed its move to settle plant and the drive ended on target")
finally:
    plant.terminate()
    plant.wait(timeout=30)
    stop(candump)
