#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Writes seeds/sdo_segmented.bin, the seed that walks fuzz_canopen.cpp's segmented-SDO rig
(SdoRig) through whole transfers: segmented upload and download, a toggle error, block
transfer, a new initiate during a transfer, a server timeout, and a client upload answered
segment by segment. Record layout: fuzz_canopen.cpp's header comment.

    tests/hal/fuzz/sdo_seed.py tests/hal/fuzz/seeds/sdo_segmented.bin
"""
import sys

NODE = 9
TO_SERVER = 0x40  # the record's data is a request to the rig's server (0x600 + node)
TO_CLIENT = 0x20  # ... a response to the rig's client (0x580 + node)


def record(fmt, data, dt=1):
    data = bytes(data).ljust(8, b"\0")
    # id 0x001 is no CANopen service: the raw frame itself only feeds the decoders.
    return bytes([dt, fmt, 0x01, 0x00, len(data)]) + data


def server(*frames, dt=1):
    return b"".join(record(TO_SERVER, f, dt) for f in frames)


def client(*frames):
    return b"".join(record(TO_CLIENT, f) for f in frames)


out = bytes([NODE - 1])
# Upload of 0x2101 (20 bytes): initiate, three segments with alternating toggles.
out += server([0x40, 0x01, 0x21, 0], [0x60], [0x70], [0x60])
# Segmented download of 10 bytes to 0x2100, then read back.
out += server([0x21, 0x00, 0x21, 0, 10], [0x00, 1, 2, 3, 4, 5, 6, 7], [0x19, 8, 9, 10])
out += server([0x40, 0x00, 0x21, 0], [0x60], [0x70])
# Toggle not alternated, block download and upload, a new initiate during a transfer.
out += server([0x40, 0x01, 0x21, 0], [0x60], [0x60])
out += server([0xC6, 0x00, 0x21, 0, 100], [0xA4, 0x00, 0x21, 0, 0x7F])
out += server([0x40, 0x01, 0x21, 0], [0x40, 0x02, 0x21, 0])
# Downloads without a size indication: 42 bytes fit the rig's 48-byte download buffer; 56 do
# not (the object would take 64): the eighth segment runs out of buffer.
for total in (42, 56):
    segments = [[0x20, 0x00, 0x21, 0]]
    for k in range(total // 7):
        last = k == total // 7 - 1
        segments.append([(0x10 if k % 2 else 0x00) | (1 if last else 0)] + [k + 1] * 7)
    out += server(*segments)
# Download longer than indicated, then a transfer left to time out (255 x 64 us > 5 ms).
out += server([0x21, 0x00, 0x21, 0, 3], [0x00, 1, 2, 3, 4, 5, 6, 7])
out += server([0x40, 0x01, 0x21, 0], [0x60])
out += server([0x70], dt=255)
# The rig's client starts by uploading 0x2101 into 24 bytes: answer it segment by segment.
out += client([0x41, 0x01, 0x21, 0, 20], [0x00] + list(b"Settle "), [0x10] + list(b"fuzz ri"),
              [0x03] + list(b"g name"))
# Its next transfer (data[0] = 0x03: download of 3 bytes to 0x2100, expedited): confirm it.
out += client([0x60, 0x00, 0x21, 0])
# The one after (data[0] = 0x60: upload of 0x2101): a server that indicates no size and sends
# more than the client's 24 bytes.
out += client([0x40, 0x01, 0x21, 0], [0x00] + [0x41] * 7, [0x10] + [0x42] * 7, [0x00] + [0x43] * 7,
              [0x11] + [0x44] * 7)
open(sys.argv[1], "wb").write(out)
