#!/usr/bin/env python3
"""Mitsuba 3's speed on the bundled scenes, for comparison with `directlab bench` on the same
machine: camera samples per second of its `direct` integrator (one light and one BSDF sample,
power-heuristic MIS: the bench's mis-power-e1b1 rows), render time only.

    pip install mitsuba            # 3.9.1 here; llvm_ad_rgb also needs: apt-get install libllvm19
    python3 experiments/mitsuba3_speed.py [--threads 2] [--spp 64] [--repeat 5]
                                          [--directlab target/release/directlab]

Prints one line per variant and scene and writes reports/bench/mitsuba3.csv (same columns as
bench.csv). For the JIT variant it also measures Mitsuba's own share of render time outside
traversal, as `directlab bench` measures directlab's (`traversal_share`; --traversal-spp 0
skips it), and that time per sample in absolute terms. Each number is the best of --repeat
renders; the JIT variant's first, compiling render is timed apart and not counted. Mitsuba needs 2 or more threads (with 1, writing an EXR
hangs), so there is no 1-thread row.

With --directlab, each Mitsuba render is paired with a directlab render of the same scene, spp,
size and thread count with the same estimator (`mis-power-e1b1-uni-area`, its render time from
--stats), the two taking turns going first, and both best-of-N numbers are reported, with the median over the N pairs of the
ratio of a directlab render to the Mitsuba render paired with it (`ratio_paired_median`): on a
shared VM whose speed drifts by tens of percent over minutes, only renders interleaved like
this compare the two renderers fairly.
"""

import argparse
import csv
import os
import platform
import statistics
import json
import subprocess
import sys
import tempfile
import time

SCENES = ["scenes/cbox/cbox.xml", "scenes/veach-mis/veach-mis.xml"]


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def directlab_speed(a, path, sized):
    """Samples/s of one directlab render (render time only, from its --stats)."""
    with tempfile.TemporaryDirectory() as d:
        cmd = [a.directlab, "render", path, "--spp", str(a.spp), "--threads", str(a.threads),
               "--strategy", "mis", "--heuristic", "power", "--emitter-samples", "1",
               "--bsdf-samples", "1", "--emitter-selection", "uniform",
               "--light-sampling", "area", "--out", os.path.join(d, "img.exr"),
               "--stats", os.path.join(d, "stats.json")]
        if sized:
            cmd += ["-D", f"res={a.res}"]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        with open(os.path.join(d, "stats.json")) as f:
            return json.load(f)["samples_per_second"]


def traversal_share(dr, mi, scene, spp, repeat):
    """Mitsuba's own share of render time outside traversal, measured as `directlab bench`
    measures directlab's: the ray mix of its `direct` integrator (a camera ray, a shadow ray
    to the emitter sample where its density is non-zero, a BSDF ray where the BSDF sample is
    valid) is drawn first, then each ray type is traced alone, best of `repeat` after a
    compiling call. Returns seconds per camera sample for (camera, shadow, BSDF) rays with
    the closest-hit query that builds the surface interaction (`ray_intersect`, as directlab's
    traversal builds its surface point) and with the bare query (`ray_intersect_preliminary`).
    """
    sensor = scene.sensors()[0]
    w, h = sensor.film().size()
    n = w * h * spp
    sampler = mi.load_dict({"type": "independent"})
    sampler.seed(1, n)
    pixel = dr.arange(mi.UInt32, n) // spp
    pos = mi.Vector2f(mi.Float(pixel % w), mi.Float(pixel // w)) + sampler.next_2d()
    ray, _ = sensor.sample_ray(0.0, 0.5, pos / mi.Vector2f(w, h), mi.Point2f(0.5))
    si = scene.ray_intersect(ray)
    valid = si.is_valid()
    ds, _ = scene.sample_emitter_direction(si, sampler.next_2d(), False, valid)
    shadow = si.spawn_ray_to(ds.p)
    shadow_on = valid & (ds.pdf > 0)
    bs, _ = si.bsdf(ray).sample(mi.BSDFContext(), si, sampler.next_1d(), sampler.next_2d(), valid)
    bray = si.spawn_ray(si.to_world(bs.wo))
    bsdf_on = valid & (bs.pdf > 0)
    dr.eval(ray, shadow, shadow_on, bray, bsdf_on)
    dr.sync_thread()

    def best(f):
        times = []
        for _ in range(repeat + 1):  # the first call compiles
            t = time.perf_counter()
            dr.eval(f())
            dr.sync_thread()
            times.append(time.perf_counter() - t)
        return min(times[1:]) / n

    full = (
        best(lambda: scene.ray_intersect(ray).t),
        best(lambda: scene.ray_test(shadow, active=shadow_on)),
        best(lambda: scene.ray_intersect(bray, active=bsdf_on).t),
    )
    bare = (
        best(lambda: scene.ray_intersect_preliminary(ray).t),
        full[1],  # an occlusion query has no lighter form
        best(lambda: scene.ray_intersect_preliminary(bray, active=bsdf_on).t),
    )
    return full, bare


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--res", type=int, default=256)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--variants", default="scalar_rgb,llvm_ad_rgb")
    ap.add_argument("--out", default="reports/bench/mitsuba3.csv")
    ap.add_argument("--directlab", help="directlab binary to interleave with Mitsuba's renders")
    ap.add_argument("--traversal-spp", type=int, default=16,
                    help="samples per pixel of the JIT variant's traversal-share measurement "
                    "(0 skips it)")
    a = ap.parse_args()
    if a.threads < 2:
        sys.exit("mitsuba3_speed.py: --threads must be 2 or more (Mitsuba hangs with 1)")
    import drjit as dr
    import mitsuba as mi

    rows = [("machine", "", cpu_model(), os.cpu_count(), 0, os.cpu_count(), "logical CPUs")]
    print(f"machine: {cpu_model()}; Mitsuba {mi.__version__}, {a.threads} threads")
    for variant in a.variants.split(","):
        try:
            mi.set_variant(variant)
        except Exception as e:  # a variant this build or machine lacks
            print(f"  {variant}: not available ({e})")
            continue
        dr.set_thread_count(a.threads)
        for path in SCENES:
            # Only the parameters the scene declares (the Veach scene has its own 768 x 512),
            # as `directlab bench` does.
            with open(path) as f:
                declared = f.read()
            params = {"spp": a.spp}
            if '<default name="res"' in declared:
                params["res"] = a.res
            scene = mi.load_file(path, **params)
            film = scene.sensors()[0].film()
            n = film.size()[0] * film.size()[1] * a.spp
            times, ours = [], []
            for k in range(a.repeat + (1 if variant.startswith("llvm") else 0)):
                paired = a.directlab and (k > 0 or not variant.startswith("llvm"))
                # The two renderers take turns going first, so that neither always runs
                # right after the other.
                if paired and k % 2 == 1:
                    ours.append(directlab_speed(a, path, "res" in params))
                t = time.perf_counter()
                img = mi.render(scene, spp=a.spp)
                dr.eval(img)
                dr.sync_thread()
                times.append(time.perf_counter() - t)
                if paired and k % 2 == 0:
                    ours.append(directlab_speed(a, path, "res" in params))
            first = ""
            if variant.startswith("llvm"):
                first = f" (first, compiling render {times[0]:.2f} s, not counted)"
                times = times[1:]
            best = min(times)
            sps = n / best
            slowest = n / max(times)
            print(
                f"  {variant:<12} {path:<32} {sps / 1e6:7.2f} M samples/s, "
                f"slowest {slowest / 1e6:.2f}{first}"
            )
            label = f"mitsuba3-{variant}-direct-e1b1"
            rows.append(("throughput", path, label, a.threads, 0, sps, "samples/s"))
            rows.append(("throughput_slowest", path, label, a.threads, 0, slowest, "samples/s"))
            if variant.startswith("llvm") and a.traversal_spp > 0:
                full, bare = traversal_share(dr, mi, scene, a.traversal_spp, a.repeat)
                for name, parts in (("", full), ("_bare", bare)):
                    share = 1.0 - sum(parts) * sps
                    # Thread time, as directlab bench's 1-thread ns per sample.
                    ns = (1.0 / sps - sum(parts)) * a.threads * 1e9
                    print(
                        f"  {'':<12} {'':<32} {share * 100:.0f}% of its render time outside "
                        f"traversal{' (bare closest-hit queries)' if name else ''}, "
                        f"{ns:.0f} ns of thread time per sample: camera "
                        f"{1e-6 / parts[0]:.1f} M rays/s, shadow {1e-6 / parts[1]:.1f} M, "
                        f"BSDF {1e-6 / parts[2]:.1f} M (per camera sample)"
                    )
                    rows.append(
                        (f"share_outside_traversal{name}", path, label, a.threads, 0, share,
                         "fraction")
                    )
                    rows.append(
                        (f"outside_traversal_per_sample{name}", path, label, a.threads, 0, ns,
                         "ns thread time")
                    )
            if ours:
                print(
                    f"  {'directlab':<12} {path:<32} {max(ours) / 1e6:7.2f} M samples/s, "
                    f"slowest {min(ours) / 1e6:.2f} (interleaved with {variant}: "
                    f"{max(ours) / sps:.2f}x its best)"
                )
                label = f"directlab-mis-power-e1b1-uni-area-interleaved-with-{variant}"
                rows.append(("throughput", path, label, a.threads, 0, max(ours), "samples/s"))
                rows.append(
                    ("throughput_slowest", path, label, a.threads, 0, min(ours), "samples/s")
                )
                # Each directlab render against the Mitsuba render beside it: a drift of
                # the VM's speed over minutes moves both of a pair, so the median of the pairs'
                # ratios is steadier than the ratio of the two bests.
                ratios = [o / (n / t) for o, t in zip(ours, times)]
                med = statistics.median(ratios)
                faster = sum(r > 1 for r in ratios)
                print(
                    f"  {'':<12} {'':<32} paired renders: median ratio {med:.2f}x, "
                    f"directlab faster in {faster} of {len(ratios)}"
                )
                rows.append(
                    ("ratio_paired_median", path, label, a.threads, len(ratios), med, "ratio")
                )
    os.makedirs(os.path.dirname(a.out) or ".", exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=os.path.dirname(a.out) or ".", suffix=".tmp")
    with os.fdopen(fd, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["section", "scene", "strategy", "threads", "n", "value", "unit"])
        w.writerows(rows)
    os.replace(tmp, a.out)
    print(f"wrote {a.out}", file=sys.stderr)


if __name__ == "__main__":
    main()
