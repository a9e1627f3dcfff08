"""A test written for Mitsuba 3's chi2 module, run by directlab: only the import changed
(`from mitsuba.chi2 import ...` became `from directlab_sampler import ...`), and the warps
use numpy where Mitsuba's use Dr.Jit. Exits 0 when both warps pass; `--wrong` halves the
cosine hemisphere's pdf, which must fail.

    PYTHONPATH=helpers/python python3 examples/samplers/mitsuba_style.py [--wrong] [OUT]"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "helpers", "python"))
from directlab_sampler import ChiSquareTest, PlanarDomain, SphericalDomain  # noqa: E402

wrong = "--wrong" in sys.argv
out = next((a for a in sys.argv[1:] if not a.startswith("--")), None)


def cosine_sample(sample):
    r, phi = np.sqrt(sample[0]), 2 * np.pi * sample[1]
    return np.array([r * np.cos(phi), r * np.sin(phi), np.sqrt(1 - sample[0])])


def cosine_pdf(p):
    return np.maximum(p[2], 0) / (2 * np.pi if wrong else np.pi)


def disk_sample(sample):
    r, phi = np.sqrt(sample[0]), 2 * np.pi * sample[1]
    return np.array([r * np.cos(phi), r * np.sin(phi)])


def disk_pdf(p):
    return np.where(p[0] ** 2 + p[1] ** 2 <= 1, 1 / np.pi, 0.0)


sphere = ChiSquareTest(domain=SphericalDomain(), sample_func=cosine_sample,
                       pdf_func=cosine_pdf, sample_dim=2, sample_count=200000)
disk = ChiSquareTest(domain=PlanarDomain(), sample_func=disk_sample, pdf_func=disk_pdf,
                     sample_dim=2, sample_count=200000, res=51)
ok = [t.run(0.01, test_count=2, out=out and os.path.join(out, n))
      for t, n in ((sphere, "sphere"), (disk, "disk"))]
print("cosine hemisphere:", "pass" if ok[0] else "FAIL", "| disk:", "pass" if ok[1] else "FAIL")
sys.exit(0 if all(ok) else 1)
