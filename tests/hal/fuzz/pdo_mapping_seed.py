#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Writes seeds/pdo_mapping.bin, the seed that walks fuzz_canopen.cpp's drive with dynamic PDO
mapping (byte 0 bit 7) through the CiA 301 procedure: RPDO2 and TPDO3 mapped over SDO and
enabled, a wrong step (a valid PDO's mapping written), NMT start, then RPDOs and SYNCs.
Record layout: fuzz_canopen.cpp's header comment.

    tests/hal/fuzz/pdo_mapping_seed.py tests/hal/fuzz/seeds/pdo_mapping.bin
"""
import struct
import sys

NODE = 4
FIRST = 0x80 | (NODE - 1)  # node = 1 + byte % 127; bit 7: writable mapping


def frame(cob, data, dt=4):
    return bytes([dt, 0, cob & 0xFF, cob >> 8, len(data)]) + bytes(data)


def download(index, sub, value, size):
    cs = {1: 0x2F, 2: 0x2B, 4: 0x23}[size]
    return frame(0x600 + NODE, [cs, index & 0xFF, index >> 8, sub] + list(struct.pack("<I", value)))


def main(path):
    out = bytearray([FIRST])
    out += download(0x1601, 1, 0x607A0020, 4)
    out += download(0x1601, 0, 1, 1)
    out += download(0x1401, 1, 0x300 + NODE, 4)
    out += download(0x1600, 0, 0, 1)  # refused: RPDO1 is valid
    out += download(0x1802, 1, 0x80000380 + NODE, 4)
    out += download(0x1A02, 0, 0, 1)
    out += download(0x1A02, 1, 0x606C0020, 4)
    out += download(0x1A02, 2, 0x60F40020, 4)
    out += download(0x1A02, 0, 2, 1)
    out += download(0x1802, 2, 2, 1)
    out += download(0x1802, 1, 0x380 + NODE, 4)
    out += frame(0x000, [0x01, NODE])  # NMT start
    for n in range(4):
        out += frame(0x200 + NODE, [0x06 if n < 2 else 0x0F, 0x00, 0, 0, 0, 0])
        out += frame(0x300 + NODE, [n, 0, 0, 0])
        out += frame(0x080, [], dt=16)
    with open(path, "wb") as f:
        f.write(out)


if __name__ == "__main__":
    main(sys.argv[1])
