#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Writes the EDS/DCF corpus of this folder: drives described in the styles vendors' tools write
(hex booleans as the Python canopen library exports them, CRLF and lower-case keys, a
manufacturer section of 1200 objects, RECORDs typed by their sub-objects, REAL limits, a DCF with
ParameterValue and NodeID, no 0x1006, no 0x60C2, no load position, static and dynamic mappings,
two RPDOs, long descriptions, velocity in TPDO1, a load encoder at the vendor's own index, the whole
feedback in one TPDO). Each is one of Settle's simulated drives (hal/eds) re-described,
so that `settle stream --bus loopback --eds F` can simulate the drive the file describes; none is
a copy of a public file. Run from anywhere: python3 make_corpus.py (check_corpus.py checks them).
With --check it writes them into a temporary folder instead and exits 1 unless they equal the
committed files byte for byte, and the folder holds no other description (ctest
testbed.eds_corpus_drift): a file edited by hand, or this script edited without re-running it, fails."""
import filecmp
import os
import re
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
CHECK = sys.argv[1:] == ["--check"]
if sys.argv[1:] not in ([], ["--check"]):
    sys.exit("usage: make_corpus.py [--check]")
OUT = tempfile.mkdtemp(prefix="settle-corpus-") if CHECK else HERE
EDS = os.path.join(HERE, "..", "..", "..", "hal", "eds")


def sections(path):
    """[(name, [(key, value)])] in file order, comments dropped."""
    out = []
    for line in open(path, encoding="utf-8"):
        line = line.strip()
        if not line or line.startswith(";"):
            continue
        if line.startswith("["):
            out.append((line[1:line.index("]")], []))
        else:
            k, v = line.split("=", 1)
            out[-1][1].append((k, v))
    return out


def write(name, secs, header, crlf=False, lower=False, hexbool=False):
    nl = "\r\n" if crlf else "\n"
    lines = [";" + h for h in header]
    for sec, keys in secs:
        lines.append("")
        lines.append("[" + (sec.lower() if lower and re.fullmatch(r"[0-9A-Fa-f]{4}(sub[0-9A-Fa-f]+)?", sec) else sec) + "]")
        for k, v in keys:
            if hexbool and k == "PDOMapping":
                v = "0x%X" % int(v, 0)
            if hexbool and k in ("ObjectType", "SubNumber") and not v.startswith("0x"):
                v = "0x%X" % int(v, 0)
            lines.append(("%s=%s" % (k.lower() if lower else k, v)))
    with open(os.path.join(OUT, name), "w", encoding="utf-8", newline="") as f:
        f.write(nl.join(lines) + nl)


def vendor(secs, vendor_name, product, drop=()):
    """Settle's drive as another vendor's: no [SettleDrive] mark, no 0x2000/0x2001 (or others
    dropped), and object lists naming what is left."""
    gone = {d.upper() for d in drop} | {"2000", "2001", "SETTLEDRIVE"}
    keep = [(n, k) for n, k in secs if n.upper()[:4] not in gone and n.upper() not in gone]
    # A static TPDO2 of 0x2000 + 0x606C becomes the velocity alone (0x2000 is not this vendor's load).
    if any(n == "1A01sub1" and ("DefaultValue", "0x20000020") in k for n, k in keep):
        keep = [(n, k) for n, k in keep if n != "1A01sub2"]
        keep = [(n, [(a, "0x606C0020" if n == "1A01sub1" and a == "DefaultValue" else
                      "1" if n == "1A01sub0" and a == "DefaultValue" else
                      "2" if n == "1A01" and a == "SubNumber" else b) for a, b in k]) for n, k in keep]
    out = []
    for n, keys in keep:
        if n in ("MandatoryObjects", "OptionalObjects", "ManufacturerObjects"):
            items = [v for k, v in keys if k.isdigit() and v.upper()[2:] not in gone]
            keys = [("SupportedObjects", str(len(items)))] + [(str(i + 1), v) for i, v in enumerate(items)]
        if n == "DeviceInfo":
            keys = [(k, vendor_name if k == "VendorName" else v) for k, v in keys]
            keys = [(k, product if k == "ProductName" else v) for k, v in keys]
        out.append((n, keys))
    return out


def manufacturer(count, start=0x3000):
    """`count` VAR objects of assorted types, as a vendor's parameter list."""
    secs, listed = [], []
    types = ["0x0007", "0x0004", "0x0006", "0x0008", "0x0005", "0x0015", "0x001B"]
    for i in range(count):
        index = "%04X" % (start + i)
        t = types[i % len(types)]
        keys = [("ParameterName", "Parameter %d" % i), ("ObjectType", "0x7"), ("DataType", t),
                ("AccessType", "rw"), ("PDOMapping", "0")]
        if t == "0x0008":
            keys += [("LowLimit", "-4.5"), ("HighLimit", "4.5"), ("DefaultValue", "0.25")]
        elif t == "0x0015":
            keys += [("LowLimit", "0x8000000000000000"), ("HighLimit", "0x7FFFFFFFFFFFFFFF"),
                     ("DefaultValue", "0xFFFFFFFFFFFFFFFF")]
        elif t == "0x001B":
            keys += [("DefaultValue", "0xFFFFFFFFFFFFFFFF")]
        else:
            keys += [("DefaultValue", "0")]
        secs.append((index, keys))
        listed.append("0x" + index)
    return secs, listed


def with_manufacturer(secs, extra, listed):
    out = [(n, k) for n, k in secs if n != "ManufacturerObjects"]
    out.append(("ManufacturerObjects", [("SupportedObjects", str(len(listed)))] +
                [(str(i + 1), v) for i, v in enumerate(listed)]))
    return out + extra


def set_key(secs, section, key, value):
    out = []
    for n, keys in secs:
        if n == section:
            keys = [(k, value if k == key else v) for k, v in keys]
            if key not in [k for k, _ in keys]:
                keys.append((key, value))
        out.append((n, keys))
    return out


settle = sections(os.path.join(EDS, "settle_drive.eds"))
dynamic = sections(os.path.join(EDS, "velocity_feedback_drive.eds"))
split = sections(os.path.join(EDS, "split_rpdo_drive.eds"))
static = sections(os.path.join(EDS, "static_mapping_drive.eds"))

HDR = ["Corpus drive (tests/testbed/corpus/make_corpus.py): %s"]

# 1. The Python canopen library's export style: hex booleans and object types.
write("01_python_export_hexbool.eds", vendor(dynamic, "Example Motion", "Servo PX"), [HDR[0] % "hex booleans"],
      hexbool=True)
# 2. A vendor with 1200 manufacturer objects (REAL32 limits, INTEGER64 two's complement).
extra, listed = manufacturer(1200)
write("02_big_manufacturer_section.eds", with_manufacturer(vendor(settle, "Big Params", "BP-1"), extra, listed),
      [HDR[0] % "1200 manufacturer objects"])
# 3. Windows tool style: CRLF, lower-case keys and object sections.
write("03_crlf_lowercase.eds", vendor(split, "Lower Case Ltd", "LC two RPDOs"), [HDR[0] % "CRLF, lower case"],
      crlf=True, lower=True)
# 4. No 0x1006 (CiA 301 asks it only of the SYNC producer).
write("04_no_1006.eds", vendor(settle, "No Cycle", "NC-1", drop=["1006"]), [HDR[0] % "no 0x1006"])
# 5. No 0x60C2 (the period through 0x1006).
write("05_no_60c2.eds", vendor(dynamic, "No Interp", "NI-1", drop=["60C2"]), [HDR[0] % "no 0x60C2"])
# 6. A DCF: ParameterValue and a NodeID.
dcf = vendor(static, "Commissioned", "DCF-3")
dcf = [("DeviceComissioning", [("NodeID", "0x03"), ("NodeName", "axis_x"), ("Baudrate", "1000")])] + dcf
dcf = set_key(dcf, "6065", "ParameterValue", "20000")
dcf = set_key(dcf, "6065", "Denotation", "following window, commissioned")
write("06_commissioned.dcf", dcf, [HDR[0] % "DCF with ParameterValue and NodeID"])
# 7. Long descriptions and a SubNumber that disagrees (a warning).
long_desc = vendor(settle, "Verbose", "V-1")
long_desc = set_key(long_desc, "FileInfo", "Description", "A drive whose description goes on " + "and on " * 120)
long_desc = set_key(long_desc, "1018", "SubNumber", "0x6")
write("07_long_lines_subnumber.eds", long_desc, [HDR[0] % "long lines, SubNumber off by one"])
# 8. Object lists that disagree with the file, NrOfRXPDO off (warnings).
lists = vendor(static, "Loose Lists", "LL-1")
lists = set_key(lists, "OptionalObjects", "SupportedObjects", "99")
lists = set_key(lists, "DeviceInfo", "NrOfRXPDO", "4")
write("08_loose_lists.eds", lists, [HDR[0] % "object lists and PDO counts that disagree"])
# 9. A RECORD typed by its sub-objects and a compact array among the manufacturer objects.
record = [("4000", [("ParameterName", "Tuning record"), ("ObjectType", "0x9"), ("DataType", "0x0040"),
                    ("SubNumber", "2")]),
          ("4000sub1", [("ParameterName", "Gain"), ("DataType", "0x0008"), ("AccessType", "rw"),
                        ("LowLimit", "0.0"), ("HighLimit", "100.0"), ("DefaultValue", "2.5")]),
          ("4000sub2", [("ParameterName", "Offset"), ("DataType", "0x0003"), ("AccessType", "rw"),
                        ("DefaultValue", "-7")]),
          ("4001", [("ParameterName", "Filter taps"), ("ObjectType", "0x8"), ("CompactSubObj", "4"),
                    ("DataType", "0x0006"), ("AccessType", "rw"), ("DefaultValue", "1"), ("PDOMapping", "0")])]
write("09_record_and_compact.eds", with_manufacturer(vendor(dynamic, "Records Inc", "R-1"), record,
                                                    ["0x4000", "0x4001"]),
      [HDR[0] % "a RECORD typed by its subs, a compact array"])
# 10. DeviceInfo contradicting 0x1018 (one identity, warned), no load position marked.
ident = vendor(settle, "Mismatch", "M-1")
ident = set_key(ident, "DeviceInfo", "ProductNumber", "0x00001234")
write("10_identity_mismatch.eds", ident, [HDR[0] % "DeviceInfo contradicts 0x1018"])

# 11. Velocity in TPDO1 by default (statusword and velocity actual; position and following error
# in TPDO2), dynamic mapping: the master maps what it needs itself.
vel = vendor(dynamic, "Velocity First", "VF-1")
vel = set_key(vel, "1A00sub2", "DefaultValue", "0x606C0020")
vel = set_key(vel, "1A01sub1", "DefaultValue", "0x60640020")
write("11_velocity_in_tpdo1.eds", vel, [HDR[0] % "velocity actual in TPDO1 (dynamic)"])
# 13 (below 12). The same split in a static mapping: statusword and position in different TPDOs.
split_static = vendor(static, "Velocity First", "VF-1S")
split_static = set_key(split_static, "1A00sub2", "DefaultValue", "0x606C0020")
split_static = set_key(split_static, "1A01sub1", "DefaultValue", "0x60640020")
# 12. The load encoder at the vendor's own index (0x2100:01 of a RECORD), marked nowhere: the user
# names it with --load-feedback 0x2100:1 (dynamic mapping: the master maps it into a TPDO).
load = [("2100", [("ParameterName", "Load encoder"), ("ObjectType", "0x9"), ("SubNumber", "3")]),
        ("2100sub0", [("ParameterName", "Highest sub-index supported"), ("ObjectType", "0x7"), ("DataType", "0x0005"),
                      ("AccessType", "const"), ("DefaultValue", "2"), ("PDOMapping", "0")]),
        ("2100sub1", [("ParameterName", "Load position"), ("ObjectType", "0x7"), ("DataType", "0x0004"),
                      ("AccessType", "ro"), ("DefaultValue", "0"), ("PDOMapping", "1")]),
        ("2100sub2", [("ParameterName", "Load encoder resolution"), ("ObjectType", "0x7"), ("DataType", "0x0007"),
                      ("AccessType", "ro"), ("DefaultValue", "1000000"), ("PDOMapping", "0")])]
write("12_load_at_2100.eds", with_manufacturer(vendor(dynamic, "Second Encoder", "SE-1"), load, ["0x2100"]),
      [HDR[0] % "a load encoder at 0x2100:01, named by the user"])
write("13_static_split_feedback.eds", split_static, [HDR[0] % "velocity in TPDO1, position in TPDO2 (static)"])
# 14. The whole feedback in one TPDO: statusword + position actual in TPDO1 (static), no 0x606C and
# no load position, TPDO2 described but mapping nothing (sub 0 = 0, its one entry unused: 0).
one_tpdo = vendor(settle, "One Feedback", "OF-1", drop=["606C"])
one_tpdo = set_key(one_tpdo, "1A01sub0", "DefaultValue", "0")
one_tpdo = set_key(one_tpdo, "1A01sub1", "ParameterName", "Mapping entry 1 (unused)")
one_tpdo = set_key(one_tpdo, "1A01sub1", "DefaultValue", "0x00000000")
write("14_one_feedback_tpdo.eds", one_tpdo, [HDR[0] % "statusword and position in TPDO1 alone, TPDO2 maps nothing (static)"])


def descriptions(folder):
    return sorted(f for f in os.listdir(folder) if f.endswith((".eds", ".dcf")))


if CHECK:
    written, committed = descriptions(OUT), descriptions(HERE)
    differ = [f for f in written if f not in committed or not filecmp.cmp(os.path.join(OUT, f), os.path.join(HERE, f),
                                                                           shallow=False)]
    extra = [f for f in committed if f not in written]
    for f in written:
        os.remove(os.path.join(OUT, f))
    os.rmdir(OUT)
    for f in differ:
        print("FAIL %s: not what make_corpus.py writes (run it, or undo the hand edit)" % f)
    for f in extra:
        print("FAIL %s: in the corpus folder, but make_corpus.py does not write it" % f)
    if differ or extra:
        sys.exit(1)
    print("the %d corpus files are what make_corpus.py writes" % len(written))
