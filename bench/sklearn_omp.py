#!/usr/bin/env python3
"""Side-by-side benchmark: our OLS trainer vs scikit-learn's OrthogonalMatchingPursuit
on the same Gaussian design matrix (every training sample a candidate centre).

Run by hand (not in CI):
    pip install scikit-learn numpy
    fogsim campaign --out /tmp/campaign
    cargo run --release -p fog-sim --example export_design -- /tmp/campaign /tmp/design
    python3 bench/sklearn_omp.py /tmp/design
"""
import json
import sys
import time

import numpy as np
from sklearn.linear_model import OrthogonalMatchingPursuit


def main():
    d = sys.argv[1] if len(sys.argv) > 1 else "/tmp/design"
    meta = json.load(open(f"{d}/meta.json"))
    n, m = meta["n_train"], meta["n_test"]
    phi = np.fromfile(f"{d}/phi_train.f32", dtype="<f4").reshape(n, n).astype(np.float64)
    phi_test = np.fromfile(f"{d}/phi_test.f32", dtype="<f4").reshape(m, n).astype(np.float64)
    y = np.fromfile(f"{d}/y_train.f64", dtype="<f8")
    y_test = np.fromfile(f"{d}/y_test.f64", dtype="<f8")
    ours = meta["ours"]
    k = ours["n_centers"]
    rows = []
    # Same number of centres as ours; precompute=False: the n x n Gram matrix would cost n^3.
    for label, kwargs in [(f"sklearn OMP, {k} atoms", dict(n_nonzero_coefs=k)),
                          ("sklearn OMP, 64 atoms", dict(n_nonzero_coefs=64))]:
        omp = OrthogonalMatchingPursuit(fit_intercept=True, precompute=False, **kwargs)
        t0 = time.perf_counter()
        omp.fit(phi, y)
        dt = time.perf_counter() - t0
        train_rms = float(np.sqrt(np.mean((y - omp.predict(phi)) ** 2)))
        held = float(np.sqrt(np.mean((y_test - omp.predict(phi_test)) ** 2)))
        rows.append((label, dt, int(np.count_nonzero(omp.coef_)), train_rms, held))
    print(f"design: {n} training samples = {n} candidate centres, {m} held-out rows, width {meta['width']}")
    print(f"{'trainer':34s} {'fit time s':>10s} {'centres':>8s} {'train rms dph':>14s} {'held-out rms dph':>17s}")
    print(f"{'ours: OLS (final fit, 1 width)':34s} {ours['final_fit_s']:10.2f} {k:8d} "
          f"{ours['train_rms_dph']:14.5f} {ours['heldout_rms_dph']:17.5f}")
    print(f"{'ours: + width search (CV)':34s} {ours['pipeline_s']:10.2f} {k:8d} {'':14s} {'':17s}")
    for label, dt, nz, tr, held in rows:
        print(f"{label:34s} {dt:10.2f} {nz:8d} {tr:14.5f} {held:17.5f}")


if __name__ == "__main__":
    main()
