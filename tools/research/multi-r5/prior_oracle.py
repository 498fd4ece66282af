#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# tools/research/multi-r5/prior_oracle.py: offline analysis of docs/results/multi-vehicle.md
# "Round five" on the CSV rows of tools/research/amfi-multi (--loose); needs
# python3-numpy (scripts/install-deps.sh). An analysis, not a test.
# Bound: the same update with each vehicle's TRUE front share as the prior mean
# (what a perfect split prior could give), sd given.
import csv,sys
import numpy as np
f=sys.argv[1]; sd=float(sys.argv[2])
rows=[r for r in csv.DictReader(l for l in open(f) if not l.startswith('#'))]
for cond in [('1','0'),('1','0.02'),('3','0'),('3','0.02')]:
    rr=[r for r in rows if (r['sensors'],r['noise'])==cond]
    ev={}
    for r in rr: ev.setdefault(int(r['event']),{})[r['vehicle']]=r
    E=sorted(ev)
    ah=np.array([[float(ev[e][v]['axle%d_kg'%k]) for v in '12' for k in (1,2)] for e in E])
    at=np.array([[float(ev[e][v]['truth_axle%d_kg'%k]) for v in '12' for k in (1,2)] for e in E])
    R=ah/at-1
    out=np.zeros_like(ah)
    for half in (0,1):
        tr=np.arange(len(E))%2!=half; te=~tr
        Rc=np.cov(R[tr].T)
        for i in np.where(te)[0]:
            C=np.diag(ah[i])@Rc@np.diag(ah[i])
            m=[at[i][0]/(at[i][0]+at[i][1]), at[i][2]/(at[i][2]+at[i][3])]
            H=np.zeros((2,4)); g=[ah[i][0]+ah[i][1], ah[i][2]+ah[i][3]]
            H[0,0]=1-m[0]; H[0,1]=-m[0]; H[1,2]=1-m[1]; H[1,3]=-m[1]
            S=np.diag([(sd*g[0])**2,(sd*g[1])**2])
            K=C@H.T@np.linalg.inv(H@C@H.T+S)
            out[i]=ah[i]-K@(H@ah[i])
    gt=np.c_[at[:,0]+at[:,1],at[:,2]+at[:,3]]
    g0=np.c_[ah[:,0]+ah[:,1],ah[:,2]+ah[:,3]]
    g1=np.c_[out[:,0]+out[:,1],out[:,2]+out[:,3]]
    e0=np.abs(g0/gt-1).ravel(); e1=np.abs(g1/gt-1).ravel()
    print(cond,'joint %.2f / %.2f %%  with the true split (sd %.3f) %.2f / %.2f %%'%(100*e0.mean(),100*e0.max(),sd,100*e1.mean(),100*e1.max()))
