"""Serve a sampler to `directlab check-sampler` (numpy only).

    from directlab_sampler import serve
    serve(sample_func, pdf_func)            # a warp
    serve(sample_func, pdf_func, eval_func) # a BSDF (--domain bsdf)

As in Mitsuba 3's ChiSquareTest: `sample_func(u)` maps uniform numbers u, an array of shape
(dims, N), to points of shape (D, N) (D = 2 on the square, disk and triangle, 3 for
directions), NaN where sampling fails; it may also return (points, weights), weights of shape
(N,) or (3, N). `pdf_func(points)` gives the density at points of shape (D, N) (per unit area,
or per steradian for directions); `eval_func(points)` a BSDF's f * cos(theta_o), shape (N,) or
(3, N). A function that takes a second argument is given the case's parameters, a dict (for
example {"alpha": 0.3}, {"wi": [x, y, z]}, {"vertices": [...]}, plus every --param).

directlab sends the uniform numbers, asks for the pdf where it needs it, and does all the
statistics:

    directlab check-sampler --domain hemisphere -- python3 my_sampler.py

Two transports carry the same messages. Pipe (the default): each request is a JSON header
line {"phase", "domain", "count", "dim", "point_dim", "params"} followed by count x dim
little-endian f64 (row-major); each reply a JSON header line {"count", "cols"} followed by
count x cols f64.
Files (`--transport files`): the program is run once per request with the path of a JSON file
holding the same header plus "input" and "output", the paths of .npy files (count x dim in,
count x cols out). A "sample" reply has columns point..., pdf, valid (1 or 0), weight...; a
"pdf" reply one column; an "eval" reply 1 or 3. {"phase": "end"} ends a piped program.
"""
import inspect
import json
import os
import sys

import numpy as np


def _takes_params(f):
    try:
        ps = inspect.signature(f).parameters.values()
    except (TypeError, ValueError):
        return False
    positional = [p for p in ps if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    return len(positional) >= 2 or any(p.kind == p.VAR_POSITIONAL for p in ps)


def _call(f, data, params):
    return f(data, params) if _takes_params(f) else f(data)


def _rows(values, n):
    """(k, N) or (N,) values as N rows of k columns."""
    v = np.asarray(values, dtype=np.float64)
    return v.reshape(n, 1) if v.ndim == 1 else v.reshape(-1, n).T


def answer(head, data, sample_func, pdf_func, eval_func=None):
    """The reply (rows x cols array) to one request; `data` is the (count, dim) payload."""
    n, params, phase = head["count"], head.get("params", {}), head["phase"]
    data = data.T
    if phase == "sample":
        res = _call(sample_func, data, params)
        weights = None
        if isinstance(res, tuple):
            res, weights = res
        pts = np.asarray(res, dtype=np.float64).reshape(-1, n)
        valid = np.all(np.isfinite(pts), axis=0)
        safe = np.where(valid, pts, 0.0)
        pdf = np.where(valid, np.asarray(_call(pdf_func, safe, params), dtype=np.float64), 0.0)
        cols = [safe.T, pdf.reshape(n, 1), valid.astype(np.float64).reshape(n, 1)]
        if weights is not None:
            cols.append(np.where(valid.reshape(n, 1), _rows(weights, n), 0.0))
        return np.hstack(cols)
    if phase == "pdf":
        return _rows(_call(pdf_func, data, params), n)
    if phase == "eval":
        if eval_func is None:
            raise ValueError("directlab asks for eval (a BSDF check) but serve() has no eval_func")
        return _rows(_call(eval_func, data, params), n)
    raise ValueError("unknown phase " + str(phase))


def _reply(out, values):
    values = np.ascontiguousarray(values, dtype="<f8")
    rows, cols = values.shape
    out.write((json.dumps({"count": rows, "cols": cols}) + "\n").encode())
    out.write(values.tobytes())
    out.flush()


def serve(sample_func, pdf_func, eval_func=None, stdin=None, stdout=None):
    """Answers directlab's requests: one request file when the program is given a .json path
    (the files transport), else requests on stdin until "end" or the pipe closes."""
    args = [a for a in sys.argv[1:] if a.endswith(".json")]
    if stdin is None and args:
        with open(args[-1]) as f:
            head = json.load(f)
        data = np.load(head["input"]).reshape(head["count"], head["dim"])
        reply = answer(head, data, sample_func, pdf_func, eval_func)
        tmp = head["output"] + ".part.npy"
        np.save(tmp, np.ascontiguousarray(reply, dtype="<f8"))
        os.replace(tmp, head["output"])
        return
    inp = stdin or sys.stdin.buffer
    out = stdout or sys.stdout.buffer
    while True:
        line = inp.readline()
        if not line:
            return
        head = json.loads(line)
        if head["phase"] == "end":
            return
        n, dim = head["count"], head["dim"]
        raw = inp.read(8 * n * dim)
        data = np.frombuffer(raw, dtype="<f8").reshape(n, dim)
        _reply(out, answer(head, data, sample_func, pdf_func, eval_func))


# Mitsuba 3's test, run by directlab: a test written for mitsuba.chi2 ports by changing its
# import (with numpy arrays in place of Dr.Jit's).


class PlanarDomain:
    """Points of the rectangle `bounds` = [[x0, x1], [y0, y1]] ([-1, 1]^2 by default, as in
    Mitsuba), density per unit area."""

    def __init__(self, bounds=None):
        self.bounds = np.array([[-1.0, 1.0], [-1.0, 1.0]] if bounds is None else bounds, float)


class SphericalDomain:
    """Unit directions, density per steradian."""


def _directlab():
    if os.environ.get("DIRECTLAB"):
        return os.environ["DIRECTLAB"]
    built = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "target",
                         "release", "directlab")
    return built if os.path.exists(built) else "directlab"


class ChiSquareTest:
    """Mitsuba's ChiSquareTest(domain, sample_func, pdf_func, sample_dim, sample_count, res,
    ires, seed): `run()` starts `directlab check-sampler --transport stdio` and answers its
    requests from this process. directlab integrates adaptively (`ires` is not used), on a
    grid of about the same number of cells; its report goes to stderr, and to `messages`."""

    def __init__(self, domain, sample_func, pdf_func, sample_dim=2, sample_count=1000000,
                 res=101, ires=4, seed=0):
        self.domain, self.sample_func, self.pdf_func = domain, sample_func, pdf_func
        self.sample_dim, self.sample_count, self.res, self.seed = (
            sample_dim, int(sample_count), int(res), int(seed))
        self.messages = ""

    def _planar(self):
        (x0, x1), (y0, y1) = self.domain.bounds
        lo, size = np.array([[x0], [y0]]), np.array([[x1 - x0], [y1 - y0]])

        def sample(u):
            res = self.sample_func(u)
            pts, w = res if isinstance(res, tuple) else (res, None)
            pts = (np.asarray(pts, dtype=np.float64) - lo) / size
            return pts if w is None else (pts, w)

        def pdf(x):
            return np.asarray(self.pdf_func(lo + x * size), dtype=np.float64) * size.prod()

        return sample, pdf

    def run(self, significance_level=0.01, test_count=1, quiet=False, out=None):
        """True when the sampler passes at `significance_level` (Sidak-split over
        `test_count` tests, as Mitsuba does); heat maps go to `out` (directlab's default
        reports/check-sampler)."""
        import subprocess
        import threading

        alpha = 1 - (1 - significance_level) ** (1 / test_count)
        if isinstance(self.domain, SphericalDomain):
            domain, res, (sample, pdf) = "sphere", (self.res + 1) // 2, (
                self.sample_func, self.pdf_func)
        else:
            domain, res, (sample, pdf) = "square", self.res, self._planar()
        args = [_directlab(), "check-sampler", "--transport", "stdio", "--domain", domain,
                "--samples", str(self.sample_count), "--dims", str(self.sample_dim),
                "--resolution", str(res), "--seed", str(self.seed), "--alpha", repr(alpha)]
        if out is not None:
            args += ["--out", str(out)]
        proc = subprocess.Popen(args, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE)
        report = []
        reader = threading.Thread(target=lambda: report.append(proc.stderr.read()))
        reader.start()
        try:
            serve(sample, pdf, stdin=proc.stdout, stdout=proc.stdin)
        except BrokenPipeError:
            pass
        finally:
            proc.stdin.close()
        proc.wait()
        reader.join()
        self.messages = report[0].decode(errors="replace")
        if not quiet:
            sys.stderr.write(self.messages)
        return proc.returncode == 0
