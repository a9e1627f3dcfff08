"""A diffuse BSDF (albedo 0.8, one-sided) checked by `directlab check-sampler --domain bsdf`:
cosine-weighted outgoing directions, the weight f cos / pdf = albedo, and eval = f cos.

    directlab check-sampler --domain bsdf -- python3 diffuse_bsdf.py

`--wrong weight` returns a weight of 1 (the albedo forgotten: chi-square cannot see it, the
weight check does); `--wrong eval` forgets the 1/pi in f (the energy check sees albedo 2.5);
`--wrong support` sends half its albedo through the surface, where the sampler never goes,
while weighting the samples it draws correctly (only the furnace check sees it: the mean
weight is half the albedo)."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "helpers", "python"))
from directlab_sampler import serve  # noqa: E402

ALBEDO = 0.8
wrong = sys.argv[sys.argv.index("--wrong") + 1] if "--wrong" in sys.argv else None


def sample(u, params):
    """Directions in the local frame (normal +z); nothing when lit from below."""
    r, phi = np.sqrt(u[0]), 2 * np.pi * u[1]
    d = np.array([r * np.cos(phi), r * np.sin(phi), np.sqrt(np.maximum(0.0, 1 - u[0]))])
    lit = params["wi"][2] > 0
    d = np.where(lit, d, np.nan)
    w = {"weight": 1.0, "support": ALBEDO / 2}.get(wrong, ALBEDO)
    weight = np.full(u.shape[1], w)
    return d, weight


def pdf(d, params):
    return np.where((params["wi"][2] > 0) & (d[2] > 0), d[2] / np.pi, 0.0)


def eval_f_cos(d, params):
    f = ALBEDO / (1.0 if wrong == "eval" else np.pi)
    if params["wi"][2] <= 0:
        return np.zeros(d.shape[1])
    if wrong == "support":
        return f / 2 * np.abs(d[2])
    return np.where(d[2] > 0, f * d[2], 0.0)


serve(sample, pdf, eval_f_cos)
