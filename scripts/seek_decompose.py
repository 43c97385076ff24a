#!/usr/bin/env python3
"""Seek error of a drift model split into misfit and noise, per seek and ambient.

Input: the CSV of `target/release/examples/misfit_rows MODEL RUNS...` (measured drift and
the model's prediction per 10 s window). For each ambient and each of seeks 1-3 (the
Monte Carlo's timing as `pipeline::seek_schedule` measures it: position 0 on the windows
(270k+10, 270k+120] s, position 180 on (270k+140, 270k+250] s, i.e. rows ending in
(270k+19, 270k+120] and (270k+149, 270k+250]; psi 108.4 deg, latitude 39.9 deg; until
2026-11-26 this used (270k+13, 270k+113] and (270k+169, 270k+269], a guess 20-30 s off at
position 180) it prints, over the runs:
bias (mean azimuth error: the model's drift misfit averaged over the dwells, systematic
across starts), std (scatter: gyro noise plus the model's) and the scatter of the model's
own predicted seek difference (the inputs' noise through the model), deg; then the mean
misfit per minute since power-on, deg/h, minus its mean after 25 min.
Usage: scripts/seek_decompose.py misfit.csv
"""
import csv,sys,math,collections
OMH=15.041067*math.cos(math.radians(39.9)); SP=math.sin(math.radians(108.4))
def az(e0,e1): return -(e0-e1)/2/(OMH*SP)*180/math.pi
f=sys.argv[1]
runs=collections.defaultdict(list)
for r in csv.DictReader(open(f)):
    runs[(float(r['ambient_c']),r['run'])].append((float(r['t_s']),float(r['before_dph']),float(r['predicted_dph'])))
def mean(x): return sum(x)/len(x) if x else float('nan')
def sd(x):
    m=mean(x); return math.sqrt(sum((v-m)**2 for v in x)/(len(x)-1))
out=[]
for amb in sorted({a for a,_ in runs}):
    rs=[v for (a,_),v in runs.items() if a==amb]
    line=f"{amb:+4.0f}:"
    for k in range(3):
        s=k*270.0
        errs=[];preds=[]
        for rows in rs:
            w0=[(b-p,p) for t,b,p in rows if s+19<t<=s+120]
            w1=[(b-p,p) for t,b,p in rows if s+149<t<=s+250]
            if len(w0)<5 or len(w1)<5: continue
            errs.append(az(mean([x for x,_ in w0]),mean([x for x,_ in w1])))
            preds.append(az(mean([p for _,p in w0]),mean([p for _,p in w1])))
        line+=f" | s{k+1} bias {mean(errs):+.4f} std {sd(errs):.4f} (pred std {sd(preds):.4f}, n{len(errs)})"
    out.append(line)
    # per-minute mean misfit (deg/h), first 12 min
    mm=[]
    for mnt in range(12):
        v=[b-p for rows in rs for t,b,p in rows if mnt*60<t<=(mnt+1)*60]
        mm.append(mean(v))
    base=mean([b-p for rows in rs for t,b,p in rows if t>1500])
    out.append("   misfit by minute (deg/h, minus late mean): "+" ".join(f"{x-base:+.4f}" for x in mm))
print("\n".join(out))
