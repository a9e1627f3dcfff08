#!/usr/bin/env python3
"""Where a render's instructions go inside one hot function, by the functions inlined into it.

The lane kernel (`li_lanes`) and the render loop inline everything they call, so callgrind and
perf name only the outer function. This runs a render under callgrind, one count per machine
instruction, and asks addr2line (with the build's line tables) for the chain of inlined calls
at each instruction; each instruction's count then goes to the function `--depth` levels below
the outer one (`camera_hits`, `light_draws`, `shade`, ...). Counts are instructions, not time:
repeatable whatever else the machine is doing, which wall time on a shared VM is not.

    RUSTFLAGS="-C target-cpu=x86-64-v3" CARGO_TARGET_DIR=/tmp/v3 cargo build --release
    python3 experiments/callgrind_phases.py /tmp/v3/release/directlab [--match li_lanes]
        [--depth 1] [--lines] -- render scenes/cbox/cbox.xml --spp 16 --threads 1 ...

Valgrind 3.19 does not decode AVX-512, so the binary must be built for x86-64-v3 (AVX2),
not with the project's `target-cpu=native` on a machine that has AVX-512.
"""

import argparse
import collections
import os
import re
import subprocess
import sys
import tempfile


def self_costs(path, pattern):
    """Self cost per instruction address of the functions whose name matches `pattern`."""
    names, costs = {}, collections.Counter()
    fn, addr, skip = None, 0, False
    with open(path) as f:
        for line in f:
            m = re.match(r"^(c?fn)=\((\d+)\)(?: (.*))?$", line.rstrip("\n"))
            if m:
                kind, idx, name = m.groups()
                if name:
                    names[idx] = name
                if kind == "fn":
                    fn = names.get(idx, idx)
                continue
            if line.startswith("calls="):
                skip = True  # the next cost line is the call's inclusive cost
                continue
            m = re.match(r"^(0x[0-9a-f]+|[+-]\d+|\*)\s+\S+\s+(\d+)", line)
            if not m:
                continue
            a, c = m.groups()
            if a.startswith("0x"):
                addr = int(a, 16)
            elif a[0] in "+-":
                addr += int(a)
            if skip:
                skip = False
                continue
            if fn and re.search(pattern, fn):
                costs[addr] += int(c)
    return costs


def inline_chains(binary, addrs):
    """Per address, its inlined call chain from the outer function inwards, as
    (function, file:line) pairs."""
    out = subprocess.run(
        ["addr2line", "-a", "-i", "-f", "-C", "-e", binary] + [hex(a) for a in addrs],
        capture_output=True, text=True, check=True,
    ).stdout.splitlines()
    chains, cur, i = {}, None, 0
    while i < len(out):
        if out[i].startswith("0x"):
            cur = int(out[i], 16)
            chains[cur] = []
            i += 1
            continue
        chains[cur].append((out[i], out[i + 1]))
        i += 2
    return {a: list(reversed(c)) for a, c in chains.items()}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("binary")
    ap.add_argument("--match", default="li_lanes", help="regex of the outer function")
    ap.add_argument("--depth", type=int, default=1, help="inlined levels to group by")
    ap.add_argument("--lines", action="store_true", help="also split by source line")
    ap.add_argument("--top", type=int, default=30)
    argv = sys.argv[1:]
    if "--" not in argv:
        ap.error("give the binary's arguments after --")
    cut = argv.index("--")
    a = ap.parse_args(argv[:cut])
    args = argv[cut + 1:]
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "callgrind.out")
        subprocess.run(
            ["valgrind", "--tool=callgrind", "--dump-instr=yes", f"--callgrind-out-file={out}",
             a.binary] + args,
            check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )
        with open(out) as f:
            total = next(int(l.split()[1]) for l in f if l.startswith("summary:"))
        costs = self_costs(out, a.match)
    chains = inline_chains(a.binary, sorted(costs))
    groups = collections.Counter()
    for addr, c in costs.items():
        chain = chains.get(addr, [])
        names = [f.split("::")[-1] + "@" + loc.rsplit("/", 1)[-1].split(":")[0]
                 for f, loc in chain]
        key = " > ".join(names[1:1 + a.depth]) or "(the function itself)"
        if a.lines and chain:
            key += "  at " + chain[-1][1].rsplit("/", 1)[-1]
        groups[key] += c
    inside = sum(costs.values())
    print(f"{total} instructions in all; {inside} ({100 * inside / total:.1f} %) "
          f"in functions matching {a.match!r}")
    for key, c in groups.most_common(a.top):
        print(f"{c:12d} {100 * c / total:5.1f} %  {key}")


if __name__ == "__main__":
    sys.exit(main())
