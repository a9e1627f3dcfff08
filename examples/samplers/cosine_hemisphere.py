"""A cosine-weighted hemisphere sampler checked by `directlab check-sampler --domain sphere`.
`--wrong cosine` claims the uniform hemisphere's pdf (the missing cosine); `--wrong horizon`
claims a pdf 20 % high within 10 degrees of the horizon; `--wrong outside` returns some points
below the hemisphere that its pdf calls impossible."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "helpers", "python"))
from directlab_sampler import serve  # noqa: E402

wrong = sys.argv[sys.argv.index("--wrong") + 1] if "--wrong" in sys.argv else None


def sample(u):
    r, phi = np.sqrt(u[0]), 2 * np.pi * u[1]
    z = np.sqrt(np.maximum(0.0, 1 - u[0]))
    if wrong == "outside":
        z = np.where(u[0] > 0.999, -z, z)
    return np.array([r * np.cos(phi), r * np.sin(phi), z])


def pdf(d):
    if wrong == "cosine":
        return np.where(d[2] > 0, 1 / (2 * np.pi), 0.0)
    p = np.maximum(d[2], 0.0) / np.pi
    if wrong == "horizon":
        p = np.where(d[2] < np.sin(np.radians(10)), 1.2 * p, p)
    return p


serve(sample, pdf)
