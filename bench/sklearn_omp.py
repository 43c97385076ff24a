#!/usr/bin/env python3
"""scikit-learn OrthogonalMatchingPursuit (35 atoms) on the same candidates as our
trainer: the Gaussian design over the exported normalised points, chosen width and
grid candidates (`fogsim train --export-design FILE`). Prints the OMP fit time (design
build excluded) and its training rms; given our pipeline's wall and CPU seconds
(argv 2, 3), also how many times faster than this OMP fit it was. Run by
bench/trainer_vs_omp.sh."""
import json
import sys
import time

import numpy as np
from sklearn.linear_model import OrthogonalMatchingPursuit


def main():
    ex = json.load(open(sys.argv[1]))
    d = ex["n_inputs"]
    pts = np.asarray(ex["points"], dtype=np.float64).reshape(-1, d)
    y = np.asarray(ex["targets_dph"], dtype=np.float64)
    cand = pts[np.asarray(ex["candidates"], dtype=np.int64)]
    w = ex["width"]
    d2 = ((pts[:, None, :] - cand[None, :, :]) ** 2).sum(axis=2)
    phi = np.exp(-d2 / (2 * w * w))
    omp = OrthogonalMatchingPursuit(n_nonzero_coefs=35, fit_intercept=True, precompute=False)
    t0 = time.perf_counter()
    omp.fit(phi, y)
    dt = time.perf_counter() - t0
    rms = float(np.sqrt(np.mean((y - omp.predict(phi)) ** 2)))
    print(f"sklearn OMP 35 atoms: {pts.shape[0]} points x {cand.shape[0]} candidates, "
          f"fit {dt:.3f} s, train rms {rms:.5f} dph")
    if len(sys.argv) >= 4:
        wall, cpu = float(sys.argv[2]), float(sys.argv[3])
        print(f"fogsim train (whole default pipeline): {wall:.2f} s wall, {cpu:.2f} s CPU; "
              f"OMP fit / pipeline wall = {dt / wall:.3f}, OMP fit / pipeline CPU = {dt / cpu:.3f}")


if __name__ == "__main__":
    main()
