#!/usr/bin/env python3
"""Reference numbers for host-sim/tests/allan_vs_allantools.rs, from allantools.

Usage: ALLAN_EXPORT_DIR=DIR cargo test -p fog-sim --test integration allan_vs_allantools::export
       python3 scripts/allantools_reference.py DIR > reference.rs.txt
Prints Rust constants: per series and deviation kind the octave (tau, dev) pairs
(allantools oadev, mdev, ohdev, tdev, totdev on the rate as data_type='freq', rate=1),
Greenhall EDFs (ci.edf_greenhall, ci.edf_totdev) and the lag-1 noise ids
(ci.autocorr_noise_id, data_type='freq').
"""
import sys

import allantools as at
import numpy as np
from allantools import ci

d = sys.argv[1]
kinds = [("Adev", at.oadev), ("Mdev", at.mdev), ("Hdev", at.ohdev), ("Tdev", at.tdev), ("Totdev", at.totdev)]
print(f"// allantools {at.__version__}, numpy {np.__version__}")
print("/// (series, kind, octave (tau_s, dev) pairs).")
print("pub type Curve = (usize, Kind, &'static [(f64, f64)]);")
print("pub const DEVS: &[Curve] = &[")
for i in range(3):
    y = np.loadtxt(f"{d}/series{i}.txt")
    for name, f in kinds:
        taus, devs, _, _ = f(y, rate=1.0, data_type="freq", taus="octave")
        pairs = ", ".join(f"({t:.1f}, {v:.10e})" for t, v in zip(taus, devs))
        print(f"    ({i}, Kind::{name}, &[{pairs}]),")
print("];")
n = len(np.loadtxt(f"{d}/series0.txt")) + 1
ms = [2 ** k for k in range(0, 12) if 2 ** k <= (n - 1) // 3]
print(f"/// (alpha, d, m, modified, edf) for n = {n} phase points, overlapping.")
print("pub const EDFS: &[(i32, usize, usize, bool, f64)] = &[")
for alpha in [2, 1, 0, -1, -2]:
    for dd, modified in [(2, False), (2, True), (3, False)]:
        for m in ms:
            try:
                e = ci.edf_greenhall(alpha=alpha, d=dd, m=m, N=n, overlapping=True, modified=modified)
            except (NotImplementedError, AssertionError):
                continue
            print(f"    ({alpha}, {dd}, {m}, {str(modified).lower()}, {e:.10e}),")
print("];")
print("/// (alpha, m, totdev edf).")
print("pub const TOTDEV_EDFS: &[(i32, usize, f64)] = &[")
for alpha in [0, -1, -2]:
    for m in ms:
        print(f"    ({alpha}, {m}, {ci.edf_totdev(n, m, alpha):.10e}),")
print("];")
print("/// (series, m, alpha) from ci.autocorr_noise_id(y, m, data_type='freq', dmax=2).")
print("pub const NOISE_IDS: &[(usize, usize, i32)] = &[")
for i in range(3):
    y = np.loadtxt(f"{d}/series{i}.txt")
    for m in ms:
        if len(y) // m < 30:
            continue
        a = ci.autocorr_noise_id(y, m, data_type="freq", dmin=0, dmax=2)[0]
        print(f"    ({i}, {m}, {a}),")
print("];")
print("/// (dev, edf, low, high) from ci.confidence_interval(dev, edf) (1 sigma).")
print("pub const INTERVALS: &[(f64, f64, f64, f64)] = &[")
for edf in [1.5, 4.0, 17.3, 250.0, 4000.0]:
    lo, hi = ci.confidence_interval(1.0, edf)
    print(f"    (1.0, {edf}, {lo:.12e}, {hi:.12e}),")
print("];")
