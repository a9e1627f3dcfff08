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
