#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Writes the inputs of the master-vs-drive fuzz harness (fuzz_servo.cpp) from a readable
description, and writes the committed seed corpus (servo_seeds/). The byte layout is the one
fuzz_servo.cpp's header comment documents; to read what an input does, run the harness on it
with FUZZ_SERVO_TRACE=1.

    tests/hal/fuzz/servo_input.py seeds DIR      # (re)write the seed corpus into DIR
"""
import struct
import sys
from pathlib import Path

OPS = ["target", "drop_tx", "drop_rx", "fail_tx", "delay_tx", "delay_rx", "random", "clear",
       "dup_rx", "dup_tx", "reorder_rx", "reorder_tx", "inject_before", "inject_after", "inject_sync"]
INJECTING = {"inject_before", "inject_after", "inject_sync"}
FILTERS = ["sync", "rpdo1", "tpdo1", "tpdo2", "heartbeat", "sdo_rx", "sdo_tx", "nmt", "emcy", "all"]
PROFILES = {"scurve": 0, "poly345": 1, "ramp_versine": 2}
FRAMES = ["nmt", "sync", "rpdo1", "rpdo1_other", "tpdo1", "tpdo2", "tpdo_other", "sdo_download",
          "sdo_raw", "emcy", "heartbeat", "garbage"]


def header(profile="scurve", distance=0.1, time=0.2, omega=22.0, submit=30, ip=False,
           following_error=False, heartbeat=True, abort_quick_stop=False, seed=1, start=0):
    flags = PROFILES[profile] | (4 if ip else 0) | (8 if following_error else 0) | \
        (16 if heartbeat else 0) | (32 if abort_quick_stop else 0)
    raw_distance = round(distance / 0.25 * 32768)
    raw_time = round((time - 0.03) / 0.001)
    raw_omega = round((omega - 10.0) / 0.25)
    assert -32768 <= raw_distance < 32768 and 0 <= raw_time < 256 and 0 <= raw_omega < 256
    return bytes([flags]) + struct.pack("<hBBBIi", raw_distance, raw_time, raw_omega, submit, seed, start)


def event(dt, op, a=0, b=0, extra=b"\0\0\0\0", side="master", filt=None):
    """One event dt ticks after the previous one. For fault ops `side` and `filt` fill `a`."""
    if op not in INJECTING:
        a |= 1 if side == "drive" else 0
        if filt is not None:
            a |= FILTERS.index(filt) << 1
    out = bytes([dt, OPS.index(op), a & 0xFF, b & 0xFF])
    if op in INJECTING:
        assert len(extra) == 4
        out += extra
    return out


def inject(dt, frame, b=0, extra=b"\0\0\0\0", when="inject_before"):
    return event(dt, when, FRAMES.index(frame), b, extra)


def seeds():
    """A few scenarios that exercise each part of the harness and pass on a correct system."""
    clean = header()
    return {
        # A move with nothing going wrong; heartbeat supervision on.
        "clean_scurve": clean,
        "clean_poly345_ip": header(profile="poly345", distance=-0.05, time=0.15, ip=True, start=-123456),
        "clean_ramp_versine": header(profile="ramp_versine", distance=0.1, time=0.167, omega=28.28),
        # Start-up through an SDO response delayed by 3 ms, then a quiet move.
        "delayed_sdo": clean + event(2, "target", side="drive", filt="sdo_tx") + event(0, "delay_tx", side="drive", b=12)
        + event(40, "clear", a=2),
        # A busy RPDO in the middle of the move (the loop holds its clock, nothing skipped).
        "busy_rpdo": clean + event(80, "target", filt="rpdo1") + event(0, "fail_tx", b=2) + event(5, "clear", a=2),
        # Duplicated TPDOs and a heartbeat from another node's traffic, mid-move.
        "dup_feedback": clean + event(60, "dup_rx", filt="tpdo1", b=3) + inject(1, "tpdo_other", b=1)
        + inject(1, "rpdo1_other") + event(5, "clear", a=2),
        # A third node's SYNC-less garbage and an EMCY of another node, before start-up ends.
        "garbage_early": clean + inject(2, "garbage", b=0x85, extra=b"\x12\x34\x56\x78") + inject(0, "emcy", b=1),
        # An SDO upload of the statusword by a third node while the move runs.
        "third_party_sdo_upload": clean + inject(70, "sdo_raw", b=0x40, extra=b"\x41\x60\x00\x00"),
    }


def main(argv):
    if len(argv) == 3 and argv[1] == "seeds":
        out = Path(argv[2])
        out.mkdir(parents=True, exist_ok=True)
        for name, data in seeds().items():
            (out / name).write_bytes(data)
        return 0
    print(__doc__, file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv))
