#!/usr/bin/env python3
"""scikit-learn OrthogonalMatchingPursuit (35 atoms) at our chosen width, on two
candidate sets: (a) our trainer's reduced grid candidates (`fogsim train
--export-design FILE`), and (b) every training point (the paper's candidate set, the
one OMP and our trainer both used before candidate reduction; skipped with
OMP_FULL=0). Prints each OMP fit time (design build excluded) and training rms; given
our pipeline's wall and CPU seconds (argv 2, 3), how many times faster the pipeline
was than each. Run by bench/trainer_vs_omp.sh."""
import os
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
        omp = OrthogonalMatchingPursuit(n_nonzero_coefs=35, fit_intercept=True, precompute=False)
        t0 = time.perf_counter()
        omp.fit(phi, y)
        dt = time.perf_counter() - t0
        rms = float(np.sqrt(np.mean((y - omp.predict(phi)) ** 2)))
        print(f"sklearn OMP 35 atoms, {name}: {pts.shape[0]} points x {cand.shape[0]} "
              f"candidates, fit {dt:.3f} s, train rms {rms:.5f} dph")
        if wall is not None:
            print(f"  fogsim train (whole default pipeline): {wall:.2f} s wall, {cpu:.2f} s CPU; "
                  f"OMP fit / pipeline wall = {dt / wall:.2f}, OMP fit / pipeline CPU = {dt / cpu:.2f}")
        del phi


if __name__ == "__main__":
    main()
