#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The test harness's own CAN node, for readiness and ordering by frames instead of sleeps
(tests/e2e, tests/cross/servo-replay; inside tools/with-vcan's guest; `settle demo` does the same in C++).

  tools/canbus.py wait-heartbeat IFACE NODE   returns once NODE's boot-up or heartbeat is on the bus
  tools/canbus.py barrier IFACE NODE          returns once NODE has answered an SDO upload of 0x1018:4:
                                              it has taken every frame sent on the bus before
Both fail (exit 1, one line) when the node does not answer within --guard seconds (default 60):
a bound on a hang, not a readiness delay.

As a module: Socket (a raw CAN socket with a large receive queue whose kernel drops are counted,
SO_RXQ_OVFL), and Sniffer (a complete capture of the bus while a test runs)."""
import argparse, select, socket, struct, sys, time

SO_RXQ_OVFL = 40      # not exported by Python's socket module
SO_RCVBUFFORCE = 33
CAN_EFF_FLAG = 0x80000000
CAN_FRAME = struct.Struct("=IB3x8s")
GUARD_S = 60.0
# The harness's marker frame (an extended id, which no CANopen node here uses or answers).
MARKER_ID = 0x1ABCDEF


class Socket:
    """A raw CAN socket. filters: [(id, mask)] (classic ids); own: also receive what it sends."""

    def __init__(self, iface="vcan0", filters=None, own=False, rcvbuf=32 << 20):
        self.s = socket.socket(socket.AF_CAN, socket.SOCK_RAW, socket.CAN_RAW)
        try:
            self.s.setsockopt(socket.SOL_SOCKET, SO_RCVBUFFORCE, rcvbuf)
        except OSError:
            self.s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf)
        self.s.setsockopt(socket.SOL_SOCKET, SO_RXQ_OVFL, 1)
        if filters is not None:
            self.s.setsockopt(socket.SOL_CAN_RAW, socket.CAN_RAW_FILTER,
                              b"".join(struct.pack("=II", i, m | 0xC0000000) for i, m in filters))  # data frames, 11-bit
        if own:
            self.s.setsockopt(socket.SOL_CAN_RAW, socket.CAN_RAW_RECV_OWN_MSGS, 1)
        self.s.bind((iface,))
        self.drops = 0  # frames the kernel dropped from this socket's queue (cumulative)

    def close(self):
        self.s.close()

    def send(self, can_id, data=b""):
        self.s.send(CAN_FRAME.pack(can_id, len(data), bytes(data).ljust(8, b"\0")))

    def recv(self, timeout):
        """(id, data bytes) or None after timeout seconds; extended ids carry CAN_EFF_FLAG."""
        if not select.select([self.s], [], [], timeout)[0]:
            return None
        msg, anc, _, _ = self.s.recvmsg(CAN_FRAME.size, socket.CMSG_SPACE(4))
        for level, kind, value in anc:
            if level == socket.SOL_SOCKET and kind == SO_RXQ_OVFL and len(value) >= 4:
                self.drops = struct.unpack("=I", value[:4])[0]
        can_id, n, data = CAN_FRAME.unpack(msg[:CAN_FRAME.size])
        return can_id, data[:n]

    def wait_for(self, match, what, alive=None, guard=GUARD_S):
        """The first frame match(id, data) accepts. Fails after `guard` seconds without one, or
        as soon as alive() says the process that should send it has gone."""
        end = time.monotonic() + guard
        while time.monotonic() < end:
            f = self.recv(0.1)
            if f is not None and match(*f):
                return f
            if alive is not None and not alive():
                raise RuntimeError(f"{what}: the process that should send it has exited")
        raise RuntimeError(f"{what}: not seen within {guard:.0f} s")

    def wait_heartbeat(self, node, alive=None, guard=GUARD_S):
        """NODE's boot-up (0x00) or heartbeat: its socket is open and it takes frames from now on."""
        return self.wait_for(lambda i, d: i == 0x700 + node and len(d) == 1, f"node {node}'s boot-up or heartbeat",
                             alive, guard)

    def barrier(self, node, alive=None, guard=GUARD_S):
        """Sends an SDO upload of 0x1018:4 (serial number, which no master here reads) to NODE and
        waits for its answer (the value or an abort). A node takes the frames of its queue in order,
        so it has taken every frame sent on the bus before this one."""
        while self.recv(0) is not None:  # answers that were already queued are not this one's
            pass
        self.send(0x600 + node, bytes([0x40, 0x18, 0x10, 0x04, 0, 0, 0, 0]))
        return self.wait_for(lambda i, d: i == 0x580 + node and len(d) == 8 and d[1:4] == b"\x18\x10\x04",
                             f"node {node}'s answer to the barrier SDO", alive, guard)


class Sniffer:
    """Captures every frame on the bus from construction until stop(), in bus order, with the
    kernel's drop count: a capture is complete when drops == 0. The frames wait in the socket's
    32 MB queue (tens of thousands of frames) and are read only by stop(), so the capture takes
    no CPU from the processes under test. stop() sends a marker frame and reads until it comes
    back: every frame sent on the bus before stop() is then in the capture."""

    def __init__(self, iface="vcan0"):
        self.sock = Socket(iface, own=True)

    def stop(self, guard=GUARD_S):
        self.sock.send(MARKER_ID | CAN_EFF_FLAG, b"\x5e\x77\x1e")
        frames = []
        self.sock.wait_for(lambda i, d: i == (MARKER_ID | CAN_EFF_FLAG) or frames.append((i, d)),
                           "the sniffer's own marker frame", guard=guard)
        self.sock.close()
        return frames


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("command", choices=["wait-heartbeat", "barrier"])
    ap.add_argument("iface")
    ap.add_argument("node", type=int)
    ap.add_argument("--guard", type=float, default=GUARD_S)
    a = ap.parse_args()
    if not 1 <= a.node <= 127:
        print("canbus: node must be 1..127", file=sys.stderr)
        return 2
    try:
        if a.command == "wait-heartbeat":
            Socket(a.iface, filters=[(0x700 + a.node, 0x7FF)]).wait_heartbeat(a.node, guard=a.guard)
        else:
            Socket(a.iface, filters=[(0x580 + a.node, 0x7FF)]).barrier(a.node, guard=a.guard)
    except (RuntimeError, OSError) as e:
        print(f"canbus: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
