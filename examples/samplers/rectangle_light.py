"""Directions from the origin to points drawn uniformly on a rectangular light, with the
solid-angle pdf d^2 / (A cos(theta_light)): a correct sampler whose density has sharp edges
(the light's silhouette).

    directlab check-sampler --domain sphere -- python3 rectangle_light.py            # passes
    directlab check-sampler --domain sphere --ires 4 -- python3 rectangle_light.py   # rejected

With --ires 4 the cells are integrated by a fixed 4 x 4 trapezoid, as Mitsuba's
ChiSquareTest does: cells cut by the silhouette get the wrong expected counts and the
correct sampler is rejected. The adaptive integration refines exactly those cells."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "helpers", "python"))
from directlab_sampler import serve  # noqa: E402

CORNER = np.array([-0.3, -0.2, 1.0])
E1 = np.array([0.8, 0.0, 0.0])
E2 = np.array([0.0, 0.5, 0.15])
NORMAL = np.cross(E1, E2)
AREA = np.linalg.norm(NORMAL)
NORMAL = NORMAL / AREA


def sample(u):
    x = CORNER[:, None] + E1[:, None] * u[0] + E2[:, None] * u[1]
    return x / np.linalg.norm(x, axis=0)


def pdf(d):
    """d^2 / (A |cos|) where the ray from the origin along d meets the rectangle, else 0."""
    denom = NORMAL @ d
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (NORMAL @ CORNER) / denom
        x = d * t - CORNER[:, None]
        a, b = (E1 @ x) / (E1 @ E1), (E2 @ x) / (E2 @ E2)  # E1 and E2 are orthogonal
        inside = (t > 0) & (a >= 0) & (a <= 1) & (b >= 0) & (b <= 1)
        p = t * t / (AREA * np.abs(denom))
    return np.where(inside, p, 0.0)


serve(sample, pdf)
