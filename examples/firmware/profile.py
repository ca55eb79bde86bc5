#!/usr/bin/env python3
"""Where the firmware's instructions go: an exact instruction profile under QEMU.

    python3 profile.py [--target TRIPLE] [--features F] [--top N]

Builds the firmware (release) for TRIPLE (default thumbv7em-none-eabihf),
runs it on its QEMU board with `-d in_asm,exec,nochain` streamed through a
FIFO, counts how often every instruction executed (each translated block's
instructions times the block's executions), and attributes each
instruction to the innermost function it was inlined from
(`arm-none-eabi-addr2line -i`), since LTO inlines the whole renderer into
one symbol. Prints the top functions and source lines. The total covers
the whole run (calibration loop, the frame, the measurement passes); the
`spin` loop is the clock calibration. Needs qemu-system-arm and
binutils-arm-none-eabi. `--annotate FILE` writes the disassembly with
each instruction's execution count, to read the hot loops.
"""
import argparse
import collections
import os
import re
import subprocess
import sys
import tempfile
import threading

BOARDS = {
    "thumbv7em-none-eabihf": ["-machine", "mps2-an386", "-cpu", "cortex-m4"],
    "thumbv7m-none-eabi": ["-machine", "mps2-an385", "-cpu", "cortex-m3"],
    "thumbv6m-none-eabi": ["-machine", "microbit"],
}


PRIMITIVE = re.compile(r"^<?(core|alloc|u8|u16|u32|u64|u128|i8|i16|i32|i64|i128|usize|isize|f32|f64|bool|char|str|\[)")


def owner(functions):
    """The crate of the innermost function in an inline chain that is not
    core's (integer, slice and iterator helpers get inlined everywhere)."""
    for fn in functions:
        if fn.startswith("__"):
            return "compiler_builtins"
        if PRIMITIVE.match(fn) and "compiler_builtins" not in fn:
            continue
        name = fn.lstrip("<")
        return name.split("::")[0].split(" as ")[0]
    return "core"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--target", default="thumbv7em-none-eabihf", choices=BOARDS)
    ap.add_argument("--features", default="")
    ap.add_argument("--top", type=int, default=25)
    ap.add_argument("--annotate", metavar="FILE",
                    help="also write the disassembly (objdump -d) with each instruction's count")
    a = ap.parse_args()
    here = os.path.dirname(os.path.abspath(__file__))
    subprocess.run(["cargo", "build", "-q", "--release", "--target", a.target,
                    "--features", a.features], cwd=here, check=True)
    elf = os.path.join(here, "target", a.target, "release", "microraster-firmware")

    tmp = tempfile.mkdtemp()
    fifo = os.path.join(tmp, "trace")
    os.mkfifo(fifo)
    qemu = subprocess.Popen(
        ["timeout", "900", "qemu-system-arm", *BOARDS[a.target], "-nographic",
         "-semihosting-config", "enable=on,target=native", "-icount", "shift=0",
         "-d", "in_asm,exec,nochain", "-D", fifo, "-kernel", elf],
        stdout=subprocess.PIPE, stdin=subprocess.DEVNULL, text=True)
    output = []
    reader = threading.Thread(target=lambda: output.extend(qemu.stdout))
    reader.start()

    blocks = {}  # block start pc -> instruction addresses
    execs = collections.Counter()  # block start pc -> executions
    ins = re.compile(r"^0x([0-9a-f]+):\s")
    trace = re.compile(r"^Trace \d+: \S+ \[[0-9a-f]+/([0-9a-f]+)/")
    current = None
    with open(fifo, errors="replace") as f:
        for line in f:
            if line.startswith("Trace"):
                m = trace.match(line)
                if m:
                    execs[int(m.group(1), 16)] += 1
                current = None
            elif line.startswith("IN:"):
                current = []
            elif current is not None:
                m = ins.match(line)
                if m:
                    if not current:
                        blocks[int(m.group(1), 16)] = current
                    current.append(int(m.group(1), 16))
    qemu.wait()
    reader.join()
    sys.stdout.write("".join(output))

    count = collections.Counter()
    for pc, n in execs.items():
        for addr in blocks.get(pc, ()):
            count[addr] += n
    addrs = sorted(count)
    res = subprocess.run(["arm-none-eabi-addr2line", "-e", elf, "-f", "-i", "-C", "-a",
                          *map(hex, addrs)], capture_output=True, text=True, check=True)
    # Output: 0xADDR, then (function, file:line) pairs, innermost first.
    lines = res.stdout.splitlines()
    chain = {}
    i = 0
    while i < len(lines):
        if lines[i].startswith("0x"):
            addr = int(lines[i], 16)
            i += 1
            pairs = []
            while i + 1 < len(lines) and not lines[i].startswith("0x"):
                pairs.append((lines[i], lines[i + 1]))
                i += 2
            chain[addr] = pairs or [("?", "?")]
        else:
            i += 1

    if a.annotate:
        dis = subprocess.run(["arm-none-eabi-objdump", "-d", "--no-show-raw-insn", elf],
                             capture_output=True, text=True, check=True).stdout
        with open(a.annotate, "w") as out:
            for line in dis.splitlines():
                m = re.match(r"^\s*([0-9a-f]+):", line)
                n = count.get(int(m.group(1), 16), 0) if m else 0
                out.write(f"{n:>9} {line}\n" if n else f"{'':>9} {line}\n")

    total = sum(count.values())
    funcs = collections.Counter()
    srcs = collections.Counter()
    crates = collections.Counter()
    for addr, n in count.items():
        pairs = chain.get(addr, [("?", "?")])
        fn, src = pairs[0]
        crates[owner([f for f, _ in pairs])] += n
        fn = re.sub(r"::h[0-9a-f]{16}$", "", fn)
        funcs[fn] += n
        srcs[re.sub(r" \(discriminator \d+\)", "", src.split("/")[-1]) + "  " + fn[-60:]] += n
    print(f"\n{total} instructions executed ({a.target}, features '{a.features}')")
    print("\nby crate: the innermost inlined function outside core (compiler_builtins = software float and 64-bit arithmetic):")
    for k, n in crates.most_common():
        print(f"{n:>11} {100 * n / total:5.1f}%  {k}")
    print("\ninnermost function:")
    for k, n in funcs.most_common(a.top):
        print(f"{n:>11} {100 * n / total:5.1f}%  {k}")
    print("\nsource line:")
    for k, n in srcs.most_common(a.top):
        print(f"{n:>11} {100 * n / total:5.1f}%  {k}")
    return qemu.returncode


if __name__ == "__main__":
    sys.exit(main())
