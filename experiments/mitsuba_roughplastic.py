"""Mitsuba 3's roughplastic evaluated at fixed directions: eval (f cos_o) and pdf, for the
configurations src/bsdf/roughplastic_tests.rs checks directlab's roughplastic against
(MITSUBA_ROUGHPLASTIC). Sampled directions are not compared: they depend on the
visible-normal sampler's mapping, which differs. Prints that Rust table.

    pip install mitsuba   (3.9.1)
    python3 experiments/mitsuba_roughplastic.py
"""
import math

import mitsuba as mi

mi.set_variant("scalar_rgb")

CONFIGS = [
    # (distribution, alpha, int_ior, diffuse_reflectance, specular_reflectance, nonlinear)
    ("beckmann", 0.1, 1.49, (0.5, 0.3, 0.1), (1.0, 1.0, 1.0), False),
    ("ggx", 0.3, 2.0, (0.9, 0.6, 0.1), (0.8, 0.7, 0.6), True),
    ("beckmann", 0.6, 1.33, (0.8, 0.8, 0.8), (0.3, 0.3, 0.3), False),
]
DIRS = [(1.0, 0.0, 0.6, 2.0), (0.8, 0.3, 0.1, 4.0), (0.2, 1.0, 0.9, 0.5), (0.05, 2.5, 0.5, 3.0)]


def d(c, phi):
    s = math.sqrt(1 - c * c)
    return mi.Vector3f(s * math.cos(phi), s * math.sin(phi), c)


print(f"// Mitsuba {mi.__version__} scalar_rgb: (distribution, alpha, int_ior, d, s, nonlinear, "
      "cos_i, phi_i, cos_o, phi_o, eval, pdf)")
for dist, alpha, ior, dr_, sr, nl in CONFIGS:
    b = mi.load_dict({"type": "roughplastic", "distribution": dist, "alpha": alpha,
                      "int_ior": ior, "ext_ior": 1.0,
                      "diffuse_reflectance": {"type": "rgb", "value": dr_},
                      "specular_reflectance": {"type": "rgb", "value": sr},
                      "nonlinear": nl})
    for ci, pi, co, po in DIRS:
        si = mi.SurfaceInteraction3f()
        si.wi = d(ci, pi)
        si.n = mi.Normal3f(0, 0, 1)
        si.sh_frame = mi.Frame3f(si.n)
        ctx = mi.BSDFContext()
        wo = d(co, po)
        e = b.eval(ctx, si, wo)
        p = b.pdf(ctx, si, wo)
        print(f"(\"{dist}\", {alpha}, {ior}, {list(dr_)}, {list(sr)}, {str(nl).lower()}, "
              f"{ci}, {pi}, {co}, {po}, [{e[0]:.7e}, {e[1]:.7e}, {e[2]:.7e}], {p:.7e}),")
