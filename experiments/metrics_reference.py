"""SSIM and FLIP of tests/data/metrics/test.png against reference.png by reference
implementations, for the test `metrics::tests::ssim_and_flip_match_reference_implementations`.

    pip install scikit-image==0.26.0 flip-evaluator==1.7
    python3 experiments/metrics_reference.py

SSIM: scikit-image's structural_similarity with Wang et al.'s settings (Gaussian window,
sigma 1.5, K1 0.01, K2 0.03, population covariances, data range 1) on the 8-bit sRGB values
/ 255, averaged over channels. FLIP: NVIDIA's flip-evaluator (the official implementation),
LDR, 67 pixels per degree, mean of the error map.
"""
import os

import flip_evaluator
import numpy as np
import skimage
from skimage.io import imread
from skimage.metrics import structural_similarity

here = os.path.join(os.path.dirname(__file__), "..", "tests", "data", "metrics")
ref = imread(os.path.join(here, "reference.png"))[..., :3].astype(np.float64) / 255.0
test = imread(os.path.join(here, "test.png"))[..., :3].astype(np.float64) / 255.0
s = structural_similarity(
    ref, test, channel_axis=2, gaussian_weights=True, sigma=1.5,
    use_sample_covariance=False, data_range=1.0, K1=0.01, K2=0.03,
)
_, mean_flip, _ = flip_evaluator.evaluate(
    ref.astype(np.float32), test.astype(np.float32), "LDR", applyMagma=False,
    parameters={"ppd": 67.0},
)
print(f"scikit-image {skimage.__version__}: SSIM = {s:.10f}, 1 - SSIM = {1 - s:.10f}")
print(f"flip-evaluator 1.7: mean FLIP = {mean_flip:.10f}")
