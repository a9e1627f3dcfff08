#!/usr/bin/env python3
"""Renders a scene with Mitsuba 3 at several seeds, one EXR per seed, for `directlab compare`
(issue 70): Mitsuba's seeds as one side, directlab's (--render-b) as the other.

    python3 experiments/mitsuba_compare.py scenes/cbox/cbox.xml -D res=64 --spp 64 \
        --seeds 8 --out /tmp/mitsuba-cbox
    directlab compare /tmp/mitsuba-cbox --render-b "scenes/cbox/cbox.xml -D res=64 --spp 64"

Mitsuba 3 from pip (`pip install mitsuba`, 3.9.1; shared/REFERENCE.md section 8), variant
scalar_rgb, two threads (with fewer, writing an EXR can hang). Its `direct` integrator is the
scene's (power heuristic, one emitter and one BSDF sample per camera sample, as directlab's
default for the bundled scenes). --light-scale multiplies every emitter's radiance (the
test's known disagreement). Each EXR is written to a temporary name and renamed, and a seed
whose EXR exists is not rendered again. Exit code 3: Mitsuba cannot be imported here.
"""

import argparse
import os
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("-D", dest="defines", action="append", default=[],
                    help="NAME=VALUE, a <default> of the scene (as directlab's -D)")
    ap.add_argument("--spp", type=int, required=True)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--first-seed", type=int, default=0)
    ap.add_argument("--light-scale", type=float, default=1.0)
    ap.add_argument("--out", required=True, help="directory of seed_NNNN.exr")
    a = ap.parse_args()
    try:
        import drjit as dr
        import mitsuba as mi
    except ImportError as e:
        print(f"Mitsuba 3 is not installed here ({e}): pip install mitsuba", file=sys.stderr)
        sys.exit(3)
    mi.set_variant("scalar_rgb")
    dr.set_thread_count(2)
    defines = {}
    for d in a.defines:
        name, sep, value = d.partition("=")
        if not sep or not name:
            sys.exit(f"-D {d}: expected NAME=VALUE")
        defines[name] = value
    if a.spp < 1 or a.seeds < 1:
        sys.exit("--spp and --seeds must be at least 1")
    try:
        scene = mi.load_file(a.scene, **defines)
    except RuntimeError as e:
        sys.exit(f"{a.scene}: Mitsuba 3 cannot load it: {e}")
    if a.light_scale != 1.0:
        params = mi.traverse(scene)
        keys = [k for k in params.keys() if k.endswith("emitter.radiance.value")]
        if not keys:
            sys.exit(f"{a.scene}: no emitter radiance to scale")
        for k in keys:
            params[k] = params[k] * a.light_scale
        params.update()
    os.makedirs(a.out, exist_ok=True)
    for s in range(a.first_seed, a.first_seed + a.seeds):
        path = os.path.join(a.out, f"seed_{s:04d}.exr")
        if os.path.exists(path):
            continue
        img = mi.render(scene, seed=s, spp=a.spp)
        tmp = os.path.join(a.out, f".seed_{s:04d}.tmp.exr")
        mi.util.write_bitmap(tmp, img, write_async=False)
        os.replace(tmp, path)
    print(f"{a.scene}: {a.seeds} seeds at {a.spp} spp by Mitsuba {mi.__version__} -> {a.out}")


if __name__ == "__main__":
    main()
