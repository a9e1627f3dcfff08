"""directlab's own warps in numpy, checked by `directlab check-sampler --case`: each maps the
uniform numbers as directlab's Rust code does, so it gets the built-in case's p-value.

    directlab check-sampler --case warp/uniform-disk -- python3 directlab_warps.py uniform-disk
    directlab check-sampler --case warp/cosine-hemisphere -- \
        python3 directlab_warps.py cosine-hemisphere
    directlab check-sampler --case warp/spherical-triangle -- \
        python3 directlab_warps.py spherical-triangle
    directlab check-sampler --case warp/beckmann-a0.5-dcos -- python3 directlab_warps.py beckmann

The spherical triangle's vertices and Beckmann's roughness come with each request."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "helpers", "python"))
from directlab_sampler import serve  # noqa: E402


def uniform_disk(u):
    r, phi = np.sqrt(u[0]), 2 * np.pi * u[1]
    return np.array([r * np.cos(phi), r * np.sin(phi)])


def uniform_disk_pdf(p):
    return np.where(p[0] ** 2 + p[1] ** 2 <= 1, 1 / np.pi, 0.0)


def concentric_disk(u):
    """Shirley-Chiu: the square [-1, 1]^2 onto the disk, wedge by wedge."""
    ox, oy = 2 * u[0] - 1, 2 * u[1] - 1
    wide = np.abs(ox) > np.abs(oy)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(wide, ox, oy)
        phi = np.where(wide, np.pi / 4 * (oy / ox), np.pi / 2 - np.pi / 4 * (ox / oy))
    zero = (ox == 0) & (oy == 0)
    return np.where(zero, 0.0, np.array([r * np.cos(phi), r * np.sin(phi)]))


def cosine_hemisphere(u):
    d = concentric_disk(u)
    return np.array([d[0], d[1], np.sqrt(np.maximum(0.0, 1 - d[0] ** 2 - d[1] ** 2))])


def cosine_hemisphere_pdf(v):
    return np.where(v[2] > 0, v[2] / np.pi, 0.0)


def _unit(v):
    return v / np.linalg.norm(v, axis=0)


def spherical_triangle(u, params):
    """Arvo's area-preserving map: the sub-triangle's area from u[0], then a point on the arc
    from b to its third vertex from u[1]."""
    a, b, c = (np.array(v, dtype=np.float64) / np.linalg.norm(v) for v in params["vertices"])

    def angle(p, q, r):  # the angle at p between the arcs to q and to r
        e1, e2 = np.cross(p, q), np.cross(p, r)
        return np.arccos(np.clip(e1 @ e2 / np.linalg.norm(e1) / np.linalg.norm(e2), -1, 1))

    alpha = angle(a, b, c)
    area = alpha + angle(b, c, a) + angle(c, a, b) - np.pi
    phi = np.pi + u[0] * area - alpha
    s, t = np.sin(phi), np.cos(phi)
    k1, k2 = t + np.cos(alpha), s - np.sin(alpha) * (a @ b)
    num = k2 + (k2 * t - k1 * s) * np.cos(alpha)
    cos_bp = np.clip(num / ((k2 * s + k1 * t) * np.sin(alpha)), -1, 1)
    c_perp = c - a * (c @ a)
    c_perp /= np.linalg.norm(c_perp)
    cp = a[:, None] * cos_bp + c_perp[:, None] * np.sqrt(np.maximum(0, 1 - cos_bp**2))
    cos_t = 1 - u[1] * (1 - b @ cp)
    cp_perp = _unit(cp - b[:, None] * (b @ cp))
    return _unit(b[:, None] * cos_t + cp_perp * np.sqrt(np.maximum(0, 1 - cos_t**2)))


def spherical_triangle_pdf(d, params):
    """1 / solid angle inside the triangle (a ray test from the origin), 0 outside."""
    a, b, c = (np.array(v, dtype=np.float64) for v in params["vertices"])
    n = np.cross(b - a, c - a)
    t = (n @ a) / (n @ d)
    x = d * t
    inside = t > 0
    for p, q in ((a, b), (b, c), (c, a)):
        inside &= np.cross(q - p, (x.T - p)) @ n >= 0
    ua, ub, uc = (v / np.linalg.norm(v) for v in (a, b, c))
    omega = 2 * np.arctan2(abs(ua @ np.cross(ub, uc)), 1 + ua @ ub + ub @ uc + uc @ ua)
    return np.where(inside, 1 / omega, 0.0)


def beckmann(u, params):
    """Normals with density D(m) cos(theta_m): tan(theta) = alpha sqrt(-ln(1 - u0))."""
    au, av = params["alpha_u"], params["alpha_v"]
    r, phi = np.sqrt(-np.log1p(-u[0])), 2 * np.pi * u[1]
    return _unit(np.array([-r * np.cos(phi) * au, -r * np.sin(phi) * av, np.ones_like(r)]))


def beckmann_pdf(m, params):
    au, av = params["alpha_u"], params["alpha_v"]
    z2 = m[2] ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        d = np.exp(-((m[0] / au) ** 2 + (m[1] / av) ** 2) / z2) / (np.pi * au * av * z2 * z2)
    return np.where((m[2] > 0) & (z2 * z2 > 0), d * m[2], 0.0)


WARPS = {
    "uniform-disk": (uniform_disk, uniform_disk_pdf),
    "concentric-disk": (concentric_disk, uniform_disk_pdf),
    "cosine-hemisphere": (cosine_hemisphere, cosine_hemisphere_pdf),
    "spherical-triangle": (spherical_triangle, spherical_triangle_pdf),
    "beckmann": (beckmann, beckmann_pdf),
}

if __name__ == "__main__":
    names = [a for a in sys.argv[1:] if a in WARPS]
    if not names:
        sys.exit("usage: directlab_warps.py " + "|".join(WARPS))
    serve(*WARPS[names[0]])
