#!/usr/bin/python3
"""Writes the seed inputs of the fuzz corpora (tests/fuzz/corpus/<target>/seed_*).

config:  every scenario in config/ and tests/scenarios/ (valid and broken).
command: CDR samples as Fast DDS puts them on the wire (encapsulation
         CDR_LE), followed by the bytes fuzz_command.cpp takes from the end
         (FuzzedDataProvider reads integers from the back): a VelocityCommand
         (even selector) and MissionCommands (odd selector), well-formed and
         hostile (NaN, unknown type, bool byte 2).
mcap:    the start of mcap_fixture's files, cut short as after a crash (reader
         mode, prefix 0x01), and a round-trip script (prefix 0x00). The
         corpus also holds seed_recorded_zstd, a complete 1.5 s ddswarm-record
         recording of a one-drone run (status, scene, drone_state; --chunk-kb 4).
Usage: make_seeds.py SRC_DIR BIN_DIR
"""
import glob
import os
import shutil
import struct
import subprocess
import sys

src, bindir = sys.argv[1], sys.argv[2]
corpus = os.path.join(src, "tests", "fuzz", "corpus")


class Cdr:
    def __init__(self):
        self.b = bytearray()

    def align(self, n):
        while len(self.b) % n:
            self.b.append(0)

    def put(self, fmt, v):
        size = struct.calcsize("<" + fmt)
        self.align(size)
        self.b += struct.pack("<" + fmt, v)
        return self

    def string(self, s):
        raw = s.encode() + b"\0"
        self.put("I", len(raw))
        self.b += raw
        return self

    def payload(self):
        return b"\x00\x01\x00\x00" + bytes(self.b)  # CDR_LE encapsulation, options 0


def velocity_command(drone=0, tick=10, v=(0.5, 0.0, 0.1), yaw=0.0, motors=1, beacon=0):
    c = Cdr()
    c.put("H", drone).put("Q", tick).put("d", 0.2)
    for x in v:
        c.put("d", x)
    c.put("d", yaw).put("B", motors).put("B", 2).put("B", 1).put("I", 3).put("Q", 77).put("B", beacon)
    c.put("H", drone).put("Q", tick).put("d", 0.2)
    for _ in range(9):
        c.put("d", 1.0)
    return c.payload()


def mission_command(type_=2, v=(1.0, 0.0, 0.0), duration=5.0, value=0.0, target=-1, leader=-1, eps=0.0):
    c = Cdr()
    c.put("I", 42).put("B", type_).put("i", target)
    for x in v:
        c.put("d", x)
    c.put("d", duration).put("d", value).put("i", leader).put("d", eps)
    c.string("gs-fuzz").put("Q", 1234).put("Q", 0)
    return c.payload()


def write(target, name, data):
    d = os.path.join(corpus, target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "seed_" + name), "wb") as f:
        f.write(data)


for path in sorted(glob.glob(os.path.join(src, "config", "*.yaml")) +
                   glob.glob(os.path.join(src, "tests", "scenarios", "*.yaml"))):
    with open(path, "rb") as f:
        data = f.read()
    if len(data) <= 16 * 1024:
        write("config", os.path.basename(path), data)

# Context bytes (read from the end): selector last, then num_drones, ticks, owner, max speed.
ctx = bytes([0x10] * 24) + bytes([6, 0])  # ..., num_drones byte 6, selector 0 (even)
write("command", "velocity_ok", velocity_command() + ctx)
write("command", "velocity_nan", velocity_command(v=(float("nan"), 0, 0)) + ctx)
write("command", "velocity_absurd", velocity_command(v=(1e9, 0, 0)) + ctx)
write("command", "velocity_bad_bool", velocity_command(motors=2) + ctx)
write("command", "velocity_beacon", velocity_command(beacon=1) + ctx)
mctx = bytes([1, 1])  # airborne flag, selector 1 (odd)
for t in range(1, 9):
    write("command", f"mission_type{t}", mission_command(type_=t, value=2.0 if t in (1, 3, 6) else 0.0) + mctx)
write("command", "mission_type42", mission_command(type_=42) + mctx)
write("command", "mission_nan", mission_command(v=(float("nan"), 0, 0)) + mctx)

tmp = os.path.join(corpus, "..", "tmp_seed.mcap")
for comp in ("none", "zstd", "lz4"):
    subprocess.run([os.path.join(bindir, "mcap_fixture"), "--compression", comp, tmp], check=True,
                   stdout=subprocess.DEVNULL)
    with open(tmp, "rb") as f:
        data = f.read()
    # The fixture is ~200 kB; its first 32 kB (header, schemas, channels,
    # complete chunks, then a cut one) keep the corpus small.
    write("mcap", "fixture_" + comp + "_cut", b"\x01" + data[: 32 * 1024])
os.remove(tmp)
write("mcap", "roundtrip", b"\x00" + bytes(range(256)) * 2)
