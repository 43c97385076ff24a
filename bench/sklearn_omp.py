#!/usr/bin/env python3
"""scikit-learn OrthogonalMatchingPursuit (35 atoms) at our chosen width, on two
candidate sets: (a) our trainer's reduced grid candidates (`fogsim train
--export-design FILE`), and (b) every training point (the paper's candidate set, the
one OMP and our trainer both used before candidate reduction; skipped with
OMP_FULL=0). Prints each OMP fit time (design build excluded; median of 5 fits in one process, and
the first, cold one) and training rms; given our pipeline's median wall and CPU seconds
(argv 2, 3), the ratio OMP fit / pipeline (above 1: the pipeline is faster). Run by bench/trainer_vs_omp.sh."""
import os
import json
import sys
import time

import numpy as np
from sklearn.linear_model import OrthogonalMatchingPursuit

REPEATS = 5


def main():
    ex = json.load(open(sys.argv[1]))
    d = ex["n_inputs"]
    pts = np.asarray(ex["points"], dtype=np.float64).reshape(-1, d)
    y = np.asarray(ex["targets_dph"], dtype=np.float64)
    w = ex["width"]
    sets = [("grid candidates", pts[np.asarray(ex["candidates"], dtype=np.int64)])]
    if os.environ.get("OMP_FULL", "1") != "0":
        sets.append(("every training point", pts))
    wall = cpu = None
    if len(sys.argv) >= 4:
        wall, cpu = float(sys.argv[2]), float(sys.argv[3])
    for name, cand in sets:
        d2 = ((pts[:, None, :] - cand[None, :, :]) ** 2).sum(axis=2)
        phi = np.exp(-d2 / (2 * w * w))
        del d2
        # precompute=False: OMP on the design itself; "auto" (scikit-learn's default)
        # precomputes the Gram matrix when there are more points than candidates.
        settings = [False, "auto"] if cand.shape[0] < pts.shape[0] else [False]
        for pre in settings:
            times = []
            for _ in range(REPEATS):
                omp = OrthogonalMatchingPursuit(
                    n_nonzero_coefs=35, fit_intercept=True, precompute=pre)
                t0 = time.perf_counter()
                omp.fit(phi, y)
                times.append(time.perf_counter() - t0)
            dt = float(np.median(times))
            rms = float(np.sqrt(np.mean((y - omp.predict(phi)) ** 2)))
            print(f"sklearn OMP 35 atoms, {name}, precompute={pre}: {pts.shape[0]} points x "
                  f"{cand.shape[0]} candidates, fit median {dt:.4f} s of {REPEATS} "
                  f"(first {times[0]:.4f} s), train rms {rms:.5f} dph")
            if wall is not None:
                print(f"  fogsim train (whole default pipeline, median process): {wall:.3f} s wall, "
                      f"{cpu:.3f} s CPU; OMP fit / pipeline wall = {dt / wall:.2f}, "
                      f"OMP fit / pipeline CPU = {dt / cpu:.2f}")
        del phi


if __name__ == "__main__":
    main()
