"""Serve a sampler to `directlab check-sampler` over stdin/stdout (numpy only).

    from directlab_sampler import serve
    serve(sample_func, pdf_func)

As in Mitsuba 3's ChiSquareTest: `sample_func(u)` maps uniform numbers u, an array of shape
(2, N), to points of shape (D, N) (D = 2 on the square and the disk, 3 for directions), NaN
where sampling fails; `pdf_func(points)` gives the density at points of shape (D, N) (per unit
area, or per steradian for directions). directlab sends the uniform numbers, asks for the pdf
where it needs it, and does all the statistics:

    directlab check-sampler --domain sphere -- python3 my_sampler.py

Protocol: each request is a JSON header line {"phase", "domain", "count", "dim"} followed by
count x dim little-endian f64 (row-major); each reply a JSON header line {"count", "cols"}
followed by count x cols f64. A "sample" reply has columns point..., pdf, valid (1 or 0); a
"pdf" reply one column. {"phase": "end"} ends the program.
"""
import json
import sys

import numpy as np


def _reply(out, values):
    values = np.ascontiguousarray(values, dtype="<f8")
    rows, cols = values.shape
    out.write((json.dumps({"count": rows, "cols": cols}) + "\n").encode())
    out.write(values.tobytes())
    out.flush()


def serve(sample_func, pdf_func, stdin=None, stdout=None):
    """Answers directlab's requests until it says "end" or closes the pipe."""
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
        data = np.frombuffer(raw, dtype="<f8").reshape(n, dim).T
        if head["phase"] == "sample":
            pts = np.asarray(sample_func(data), dtype=np.float64)
            valid = np.all(np.isfinite(pts), axis=0)
            safe = np.where(valid, pts, 0.0)
            pdf = np.where(valid, np.asarray(pdf_func(safe), dtype=np.float64), 0.0)
            _reply(out, np.vstack([safe, pdf, valid.astype(np.float64)]).T)
        elif head["phase"] == "pdf":
            _reply(out, np.asarray(pdf_func(data), dtype=np.float64).reshape(n, 1))
        else:
            raise ValueError("unknown phase " + str(head["phase"]))
