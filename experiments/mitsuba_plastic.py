"""Mitsuba 3's plastic evaluated at fixed directions: eval (f cos_o), pdf, and the specular
sample's weight and probability, for the configurations src/bsdf/plastic_tests.rs checks
directlab's plastic against (MITSUBA_PLASTIC). Prints that Rust table.

    pip install mitsuba   (3.9.1)
    python3 experiments/mitsuba_plastic.py
"""
import math

import mitsuba as mi

mi.set_variant("scalar_rgb")

CONFIGS = [
    # (int_ior, diffuse_reflectance, specular_reflectance, nonlinear)
    (1.49, (0.5, 0.3, 0.1), (1.0, 1.0, 1.0), False),
    (2.0, (0.9, 0.6, 0.1), (0.8, 0.7, 0.6), True),
    (1.33, (0.8, 0.8, 0.8), (0.3, 0.3, 0.3), False),
]
DIRS = [(1.0, 0.0, 0.6, 2.0), (0.8, 0.3, 0.1, 4.0), (0.2, 1.0, 0.9, 0.5), (0.05, 2.5, 0.5, 3.0)]


def d(c, phi):
    s = math.sqrt(1 - c * c)
    return mi.Vector3f(s * math.cos(phi), s * math.sin(phi), c)


print(f"// Mitsuba {mi.__version__} scalar_rgb: (int_ior, d, s, nonlinear, cos_i, phi_i, "
      "cos_o, phi_o, eval, pdf, specular weight, specular probability)")
for ior, dr_, sr, nl in CONFIGS:
    b = mi.load_dict({"type": "plastic", "int_ior": ior, "ext_ior": 1.0,
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
        bs, w = b.sample(ctx, si, 0.0, mi.Point2f(0.5, 0.5))
        print(f"({ior}, {list(dr_)}, {list(sr)}, {str(nl).lower()}, {ci}, {pi}, {co}, {po}, "
              f"[{e[0]:.7e}, {e[1]:.7e}, {e[2]:.7e}], {p:.7e}, "
              f"[{w[0]:.7e}, {w[1]:.7e}, {w[2]:.7e}], {bs.pdf:.7e}),")
