"""Directional albedo of Mitsuba 3's roughconductor with a lossless Fresnel term (eta 0, k 1:
|r| = 1 at every angle), by BSDF sampling: the single-scattering albedo of the Smith
microfacet model that directlab's rough conductor must reproduce. Prints the Rust table that
src/bsdf/roughconductor_tests.rs holds (MITSUBA_ALBEDO), with each value's standard error.

    pip install mitsuba   (3.9.1; llvm_ad_rgb needs apt-get install libllvm19)
    python3 experiments/mitsuba_albedo.py
"""
import math

import drjit as dr
import mitsuba as mi

dr.set_thread_count(2)
mi.set_variant("llvm_ad_rgb")

N = 1 << 22
ALPHAS = [0.3, 0.5, 0.8, 1.0]
COSINES = [1.0, 0.7, 0.3, 0.1]


def albedo(dist, alpha, cos_i, seed):
    b = mi.load_dict({"type": "roughconductor", "distribution": dist, "alpha": alpha,
                      "eta": 0.0, "k": 1.0, "sample_visible": True})
    si = dr.zeros(mi.SurfaceInteraction3f, N)
    si.wi = mi.Vector3f(math.sqrt(1 - cos_i * cos_i), 0, cos_i)
    si.n = mi.Normal3f(0, 0, 1)
    si.sh_frame = mi.Frame3f(si.n)
    rng = mi.PCG32(N, initstate=seed)
    _, w = b.sample(mi.BSDFContext(), si, rng.next_float32(),
                    mi.Point2f(rng.next_float32(), rng.next_float32()))
    x = mi.Float64(w.x)
    mean = dr.sum(x)[0] / N
    var = dr.sum(x * x)[0] / N - mean * mean
    return mean, math.sqrt(var / N)


print(f"// Mitsuba {mi.__version__}, llvm_ad_rgb, {N} samples per value: (cos_i, albedo, std error)")
for dist in ["beckmann", "ggx"]:
    for alpha in ALPHAS:
        row = []
        for i, c in enumerate(COSINES):
            m, se = albedo(dist, alpha, c, 1 + i)
            row.append(f"({c}, {m:.6f}, {se:.1e})")
        print(f'("{dist}", {alpha}, [{", ".join(row)}]),')
