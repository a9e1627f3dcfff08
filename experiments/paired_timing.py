#!/usr/bin/env python3
"""Paired render timing of two directlab builds: is B faster than A, beyond the machine's noise?

On a shared VM a render's speed moves by 10 % or more from one minute to the next, and the
second of two back-to-back renders tends to run faster than the first. So the two builds
render the same scene in pairs, in ABBA order (each pair's order alternates, cancelling that
bias), and the summary is per pair: the median of B's samples/s over A's, how many pairs B
won, and the best of each. The last pair's images are compared byte for byte, since most
render-loop changes are meant to leave them identical.

    python3 experiments/paired_timing.py OLD_BINARY NEW_BINARY [--pairs 16] [--scene cbox]
        [--strategy "--strategy light"] [-- extra render arguments]

The strategy defaults to power MIS with one sample per technique and power emitter choice.

Build the baseline from a worktree (git worktree add /tmp/base COMMIT; cargo build --release
there) so that both binaries use the same flags.
"""

import argparse
import filecmp
import os
import re
import shlex
import statistics
import subprocess
import sys
import tempfile

SCENES = {
    "cbox": ["scenes/cbox/cbox.xml", "--spp", "64"],
    "veach": ["scenes/veach-mis/veach-mis.xml", "--spp", "32"],
    "plastic": ["scenes/cbox-plastic/cbox-plastic.xml", "-D", "res=256", "--spp", "64"],
}
STRATEGY = ["--strategy", "mis", "--heuristic", "power", "--emitter-selection", "power"]


def render(binary, args, out):
    """Samples per second of one 1-thread render, as the renderer reports it."""
    cmd = [binary, "render", *args, "--threads", "1", "--out", out]
    run = subprocess.run(cmd, capture_output=True, text=True)
    text = run.stdout + run.stderr
    if run.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed ({run.returncode}):\n{text}")
    m = re.search(r"\(([0-9.]+) M samples/s", text)
    if not m:
        sys.exit(f"no 'M samples/s' in the output of {' '.join(cmd)}:\n{text}")
    return float(m.group(1))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("a", help="baseline binary")
    ap.add_argument("b", help="candidate binary")
    ap.add_argument("--pairs", type=int, default=16)
    ap.add_argument("--scene", choices=sorted(SCENES), default="cbox")
    ap.add_argument("--strategy", default=shlex.join(STRATEGY),
                    help="the strategy's render arguments, as one string")
    argv = sys.argv[1:]
    cut = argv.index("--") if "--" in argv else len(argv)
    a = ap.parse_args(argv[:cut])
    extra = argv[cut + 1 :]
    for binary in (a.a, a.b):
        if not (os.path.isfile(binary) and os.access(binary, os.X_OK)):
            sys.exit(f"{binary}: not an executable file (expected a directlab binary)")
    args = SCENES[a.scene] + shlex.split(a.strategy) + extra
    ratios, best = [], {"a": 0.0, "b": 0.0}
    with tempfile.TemporaryDirectory() as tmp:
        outs = {k: os.path.join(tmp, f"{k}.exr") for k in "ab"}
        for i in range(a.pairs):
            order = "ab" if i % 2 == 0 else "ba"
            speed = {k: render(getattr(a, k), args, outs[k]) for k in order}
            ratios.append(speed["b"] / speed["a"])
            for k in "ab":
                best[k] = max(best[k], speed[k])
            print(f"pair {i + 1:2} ({order.upper()}): A {speed['a']:.2f}  B {speed['b']:.2f}"
                  f"  B/A {ratios[-1]:.3f}", flush=True)
        identical = filecmp.cmp(outs["a"], outs["b"], shallow=False)
    wins = sum(r > 1.0 for r in ratios)
    print(f"B/A median {statistics.median(ratios):.3f}, B won {wins} of {len(ratios)} pairs, "
          f"best A {best['a']:.2f} B {best['b']:.2f} M samples/s; images "
          f"{'identical' if identical else 'differ'}")


if __name__ == "__main__":
    main()
