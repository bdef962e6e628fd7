#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""tools/canopen_decode.py, the tests' independent decoder, on a log whose frames are known: tshark's
CANopen dissector names every type the tests count, finds the one malformed frame (an SDO request
cut to two bytes) and no other, the CLI exits 1 for it and 0 without it, and a line that is not a
candump frame is refused with its line number (exit 2). And the same through `--serve`, the host's
decoder a user-mode-linux guest asks over its console (tools/with-vcan): here over a pseudo-terminal
in raw mode, as the guest's console is."""
import os, subprocess, sys, tempfile, tty

sys.dont_write_bytecode = True
TOOLS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools")
sys.path.insert(0, TOOLS)
import canopen_decode  # noqa: E402

# (candump frame, the type the dissector must give it); node 1 and node 0x7F.
FRAMES = [("000#0101", "nmt"), ("080#", "sync"), ("081#0081100000000000", "emcy"), ("0FF#1081100000000000", "emcy"),
          ("181#0000000000000000", "tpdo1"), ("201#0F0001000000", "rpdo1"), ("281#01", "tpdo2"), ("301#02", "rpdo2"),
          ("381#03", "tpdo3"), ("401#04", "rpdo3"), ("481#05", "tpdo4"), ("501#06", "rpdo4"),
          ("581#4318100401000000", "sdo_tx"), ("601#4018100400000000", "sdo_rx"), ("701#00", "heartbeat"),
          ("77F#05", "heartbeat"), ("1ABCDEF0#5E771E", "other")]
MALFORMED = ("601#4018", "sdo_rx")


def check(cond, msg):
    if not cond:
        print("FAIL:", msg)
        sys.exit(1)
    print("ok:", msg)


def write(path, frames):
    with open(path, "w") as f:
        for i, (text, _) in enumerate(frames):
            f.write(f"(1700000000.{i:06d}) vcan0 {text}\n")


def cli(*args):
    return subprocess.run([sys.executable, os.path.join(TOOLS, "canopen_decode.py"), *args], capture_output=True,
                          text=True, timeout=300)


with tempfile.TemporaryDirectory(prefix="settle-decode-test-") as d:
    frames = FRAMES[:9] + [MALFORMED] + FRAMES[9:]
    log = os.path.join(d, "known.log")
    write(log, frames)
    dec = canopen_decode.decode(log)
    check(dec.types == [t for _, t in frames], f"every frame's type as the dissector reads it: {dec.summary()}")
    check([n for n, _ in dec.errors] == [10], f"the one malformed frame, and only it: {dec.errors}")
    check(cli(log).returncode == 1, "the CLI exits 1 for a log with a malformed frame")
    clean = os.path.join(d, "clean.log")
    write(clean, FRAMES)
    r = cli("--json", clean)
    check(r.returncode == 0 and '"errors": []' in r.stdout, f"and 0 without it: {r.stdout.strip()}")
    bad = os.path.join(d, "bad.log")
    with open(bad, "w") as f:
        f.write("(1700000000.000000) vcan0 080#\n(1700000000.000001) vcan0 080#XYZ\n")
    r = cli(bad)
    check(r.returncode == 2 and f"{bad}:2: not a candump -L frame line" in r.stderr, f"a bad line refused: {r.stderr}")

    # --serve at the far end of a raw pseudo-terminal, as with-vcan wires it to the guest's console.
    master, slave = os.openpty()
    tty.setraw(slave)
    server = subprocess.Popen([sys.executable, os.path.join(TOOLS, "canopen_decode.py"), "--serve"], stdin=master,
                              stdout=master, stderr=subprocess.PIPE, text=True)
    try:
        os.write(slave, b"a kernel message on the console\n")
        os.environ["SETTLE_DECODE_CHANNEL"] = os.ttyname(slave)
        remote = canopen_decode.decode(log)
        check(remote.types == dec.types and remote.errors == dec.errors and remote.counts == dec.counts,
              f"decoded by the server: the same types, counts and malformed frame ({remote.summary()})")
        try:
            canopen_decode.decode(bad)
            check(False, "the server refuses a bad line")
        except canopen_decode.BadLog as e:
            check(f"{bad}:2: not a candump -L frame line" in str(e), f"the server refuses a bad line: {e}")
        os.write(slave, b"settle-decode only-two-words\n")
        check(os.read(slave, 4096).startswith(b"error not a request"), "a malformed request is answered as such")
    finally:
        del os.environ["SETTLE_DECODE_CHANNEL"]
        os.close(slave)
        server.terminate()
        _, err = server.communicate(timeout=60)
        os.close(master)
    check(err.startswith("a kernel message on the console"), f"any other line goes to the console's record: {err!r}")
