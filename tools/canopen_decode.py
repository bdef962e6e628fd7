#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""An independent decoder for Settle's bus logs: Wireshark's CANopen dissector (Debian's tshark,
installed by tools/setup) reads a candump log (`candump -L` format, what --candump and the demo's
bus.log hold) and says what each frame is. The log is converted here to a pcap file of
LINKTYPE_CAN_SOCKETCAN (227) records, the kernel's struct can_frame with the identifier in network
byte order, and decoded with `tshark -d can.subdissector,canopen`; the frame types are tshark's
(its function code and node-ID fields), never this script's reading of the identifiers.

  tools/canopen_decode.py LOG...           each log's frames per type; exit 1 when tshark marks a
                                           frame malformed or with an expert error, 2 on bad input
  tools/canopen_decode.py --json LOG...    the same as one JSON object per log, one a line
  tools/canopen_decode.py --pcap OUT LOG   also keep the pcap file (open it in Wireshark)
  tools/canopen_decode.py --serve          decode for another machine (see below)

A user-mode-linux guest (tools/with-vcan) runs tshark twenty times slower than its host: every page
fault of Wireshark's 100 MB of libraries is a round trip to the host kernel. There, with-vcan runs
`--serve` on the host as the guest's console and names the console in SETTLE_DECODE_CHANNEL:
decode() then asks the host to decode the log (both see the same files) and reads back what tshark
found, from a file the host wrote. Requests and replies are one line each: "settle-decode LOG OUT"
-> "ok" (OUT holds the Decoded as JSON) or "bad-log MESSAGE" / "error MESSAGE"; any other line
(the guest kernel's messages) is written to stderr and not answered.

As a module: decode(path) -> Decoded (counts per type, the frames tshark found wrong)."""
import argparse, fcntl, json, os, select, shutil, struct, subprocess, sys, tempfile

LINKTYPE_CAN_SOCKETCAN = 227
CAN_EFF_FLAG, CAN_RTR_FLAG = 0x80000000, 0x40000000
CANFD_FDF = 0x04  # struct canfd_frame.flags: this is an FD frame (the pcap's byte 5)
# A line is at most about 200 characters (64 data bytes in hex); a log at most this many lines.
MAX_LINE = 512
MAX_FRAMES = 10_000_000
TSHARK_TIMEOUT_S = 600
PI_ERROR = 0x00800000  # expert severity "error" (epan/proto.h); a malformed frame has it too

# tshark's CANopen function codes (canopen.function_code; the COB-ID's top four bits, as the
# dissector reads them) with its node-ID field: the frame types counted. SYNC and EMCY share code
# 1: the dissector tells them apart by the node-ID (0: SYNC).
TYPES = {0x0: "nmt", 0x2: "time", 0x3: "tpdo1", 0x4: "rpdo1", 0x5: "tpdo2", 0x6: "rpdo2", 0x7: "tpdo3",
         0x8: "rpdo3", 0x9: "tpdo4", 0xA: "rpdo4", 0xB: "sdo_tx", 0xC: "sdo_rx", 0xE: "heartbeat", 0xF: "lss"}

# The types a master sends (to a node) and those a node sends, for counting a session's frames.
MASTER_TYPES = ("nmt", "sync", "time", "rpdo1", "rpdo2", "rpdo3", "rpdo4", "sdo_rx")
NODE_TYPES = ("emcy", "tpdo1", "tpdo2", "tpdo3", "tpdo4", "sdo_tx", "heartbeat")


class BadLog(ValueError):
    pass


def read_candump(path):
    """[(seconds, microseconds, can_id with flags, fd, data)] of a candump -L log; BadLog names the
    line that is not a frame."""
    frames = []
    with open(path, "rb") as f:
        for n, raw in enumerate(f, 1):
            if len(raw) > MAX_LINE:
                raise BadLog(f"{path}:{n}: line longer than {MAX_LINE} bytes")
            if len(frames) >= MAX_FRAMES:
                raise BadLog(f"{path}: more than {MAX_FRAMES} frames")
            parts = raw.decode("ascii", "replace").split()
            try:
                if len(parts) != 3 or not (parts[0].startswith("(") and parts[0].endswith(")")) or "#" not in parts[2]:
                    raise ValueError
                sec, usec = parts[0][1:-1].split(".")
                cid_text, body = parts[2].split("#", 1)
                cid = int(cid_text, 16)
                if len(cid_text) == 8:
                    cid |= CAN_EFF_FLAG
                elif len(cid_text) != 3 or cid > 0x7FF:
                    raise ValueError
                fd = body.startswith("#")
                if fd:
                    body = body[2:]  # the BRS/ESI digit
                if body.startswith("R") and not fd:
                    frames.append((int(sec), int(usec), cid | CAN_RTR_FLAG, False, b""))
                    continue
                data = bytes.fromhex(body)
                if len(data) > (64 if fd else 8) or len(usec) != 6:
                    raise ValueError
                frames.append((int(sec), int(usec), cid, fd, data))
            except ValueError:
                raise BadLog(f"{path}:{n}: not a candump -L frame line: {raw[:120]!r}") from None
    return frames


def write_pcap(frames, out):
    """A classic pcap file (microsecond timestamps) of LINKTYPE_CAN_SOCKETCAN records."""
    with open(out, "wb") as f:
        f.write(struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, LINKTYPE_CAN_SOCKETCAN))
        for sec, usec, cid, fd, data in frames:
            size = 64 if fd else 8
            record = struct.pack(">IBBBB", cid, len(data), CANFD_FDF if fd else 0, 0, 0) + data.ljust(size, b"\0")
            f.write(struct.pack("<IIII", sec, usec, len(record), len(record)) + record)


class Decoded:
    """What tshark made of a log: counts per type (TYPES' names, "sync", "emcy", "other" for a
    frame it did not decode as CANopen), and the frames it marked malformed or with an expert
    error, as (frame number = line in the log, its Info column)."""

    def __init__(self, path, frames):
        self.path, self.frames = path, frames
        self.counts = {}
        self.errors = []
        self.types = []  # per frame, in the log's order

    def count(self, *names):
        return sum(self.counts.get(n, 0) for n in names)

    def summary(self):
        return ", ".join(f"{k} {v}" for k, v in sorted(self.counts.items())) or "no frames"


def tshark():
    found = shutil.which("tshark")
    if found is None:
        raise RuntimeError("tshark is not installed (Debian package tshark; tools/setup installs it)")
    return found


def decode_pcap(pcap, path, n_frames):
    fields = ["frame.number", "canopen.function_code", "canopen.node_id", "_ws.malformed", "_ws.expert.severity",
              "_ws.col.Info"]
    cmd = [tshark(), "-n", "-r", pcap, "-d", "can.subdissector,canopen", "-T", "fields", "-E", "separator=\t",
           "-E", "occurrence=a", "-E", "aggregator=,"]
    for field in fields:
        cmd += ["-e", field]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=TSHARK_TIMEOUT_S,
                       env={**os.environ, "LC_ALL": "C"})
    if r.returncode != 0:
        raise RuntimeError(f"tshark failed on {path} (exit {r.returncode}): {r.stderr.strip()[-800:]}")
    d = Decoded(path, n_frames)
    for line in r.stdout.splitlines():
        cells = (line.split("\t") + [""] * len(fields))[:len(fields)]
        number, code, node, malformed, severity, info = cells
        if not code:
            kind = "other"
        else:
            fc = int(code.split(",")[0], 16)
            kind = ("sync" if int(node.split(",")[0] or "0", 16) == 0 else "emcy") if fc == 1 else TYPES.get(fc, "other")
        d.types.append(kind)
        d.counts[kind] = d.counts.get(kind, 0) + 1
        worst = max((int(s, 0) for s in severity.split(",") if s), default=0)
        if malformed or worst >= PI_ERROR:
            d.errors.append((int(number), info))
    if len(d.types) != n_frames:
        raise RuntimeError(f"tshark decoded {len(d.types)} of the {n_frames} frames of {path}")
    return d


def decode(path, keep_pcap=None):
    """Decodes the candump log at `path` with tshark; keep_pcap: where to leave the pcap file."""
    channel = os.environ.get("SETTLE_DECODE_CHANNEL")
    if channel and keep_pcap is None:
        return decode_remote(channel, path)
    frames = read_candump(path)
    with tempfile.TemporaryDirectory(prefix="settle-decode-") as tmp:
        pcap = keep_pcap or os.path.join(tmp, "bus.pcap")
        write_pcap(frames, pcap)
        return decode_pcap(pcap, path, len(frames))


MAX_REPLY = 4096
REQUEST = "settle-decode"


def to_json(d):
    return {"path": d.path, "frames": d.frames, "counts": d.counts, "errors": d.errors, "types": d.types}


def from_json(j):
    d = Decoded(j["path"], j["frames"])
    d.counts, d.types = j["counts"], j["types"]
    d.errors = [tuple(e) for e in j["errors"]]
    return d


def decode_remote(channel, path):
    """decode(path) done by `--serve` at the other end of the console `channel` (one request at a
    time: the channel is locked while it is in use)."""
    path = os.path.realpath(path)
    with tempfile.TemporaryDirectory(prefix="settle-decode-") as tmp:
        out = os.path.join(tmp, "decoded.json")
        if any(c.isspace() for c in path + out):
            raise BadLog(f"{path}: a log decoded through {channel} must have no white space in its path")
        fd = os.open(channel, os.O_RDWR | os.O_NOCTTY)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)
            os.write(fd, f"{REQUEST} {path} {out}\n".encode())
            reply = b""
            while not reply.endswith(b"\n"):
                ready, _, _ = select.select([fd], [], [], TSHARK_TIMEOUT_S)
                chunk = os.read(fd, MAX_REPLY) if ready else b""
                if not chunk or len(reply) + len(chunk) > MAX_REPLY:
                    raise RuntimeError(f"no answer from the decoder at the other end of {channel}")
                reply += chunk
        finally:
            os.close(fd)  # releases the lock
        kind, _, message = reply.decode("utf-8", "replace").strip().partition(" ")
        if kind == "bad-log":
            raise BadLog(message)
        if kind != "ok":
            raise RuntimeError(message or f"the decoder at the other end of {channel} answered '{kind}'")
        with open(out, encoding="utf-8") as f:
            return from_json(json.load(f))


def serve(inp, outp):
    """Answers decode requests, one line each, until the input ends (see the module's text)."""
    for line in inp:
        parts = line.split()
        if not parts or parts[0] != REQUEST:
            sys.stderr.write(line)
            sys.stderr.flush()
            continue
        if len(parts) != 3:
            reply = f"error not a request: {line.strip()[:120]!r}"
        else:
            try:
                d = decode(parts[1])
                try:
                    with open(parts[2], "w", encoding="utf-8") as f:
                        json.dump(to_json(d), f)
                    reply = "ok"
                except OSError as e:
                    reply = f"error cannot write the answer: {e}"
            except (BadLog, OSError) as e:  # the log: as decode() here reports it (exit 2)
                reply = f"bad-log {e}"
            except (RuntimeError, subprocess.TimeoutExpired) as e:
                reply = f"error {e}"
        outp.write(" ".join(reply.split())[:MAX_REPLY - 2] + "\n")
        outp.flush()
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("logs", nargs="*", metavar="LOG")
    ap.add_argument("--serve", action="store_true", help="answer decode requests on stdin (tools/with-vcan)")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--pcap", metavar="OUT", help="keep the pcap file (one LOG only)")
    a = ap.parse_args()
    if a.serve:
        os.environ.pop("SETTLE_DECODE_CHANNEL", None)  # decode here
        return serve(sys.stdin, sys.stdout)
    if not a.logs:
        print("canopen_decode: give at least one LOG (or --serve)", file=sys.stderr)
        return 2
    if a.pcap and len(a.logs) != 1:
        print("canopen_decode: --pcap takes one LOG", file=sys.stderr)
        return 2
    bad = False
    for path in a.logs:
        try:
            d = decode(path, a.pcap)
        except (BadLog, OSError) as e:
            print(f"canopen_decode: {e}", file=sys.stderr)
            return 2
        except (RuntimeError, subprocess.TimeoutExpired) as e:
            print(f"canopen_decode: {e}", file=sys.stderr)
            return 1
        bad = bad or bool(d.errors)
        if a.json:
            print(json.dumps({"log": path, "frames": d.frames, "counts": d.counts,
                              "errors": [{"frame": n, "info": i} for n, i in d.errors]}))
        else:
            print(f"{path}: {d.frames} frames: {d.summary()}; {len(d.errors)} malformed or in error")
            for n, info in d.errors[:20]:
                print(f"  frame {n}: {info}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
