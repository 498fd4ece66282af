#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# tools/research/multi-r5/prior_offline.py: offline analysis of docs/results/multi-vehicle.md
# "Round five" on the CSV rows of tools/research/amfi-multi (--loose); needs
# python3-numpy (scripts/install-deps.sh). An analysis, not a test.
# Offline bound on a front-share prior: posterior mean of the 4 axle loads
# given the joint estimate with an empirical error covariance (relative,
# estimated on the other half of the events) and share ~ N(mu, sd).
import csv,sys
import numpy as np
f=sys.argv[1]; mu=float(sys.argv[2]); sd=float(sys.argv[3])
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
            # constraints: front - mu*(front+rear) ~ N(0, (sd*gvw)^2)
            H=np.zeros((2,4)); g=[ah[i][0]+ah[i][1], ah[i][2]+ah[i][3]]
            H[0,0]=1-mu; H[0,1]=-mu; H[1,2]=1-mu; H[1,3]=-mu
            S=np.diag([(sd*g[0])**2,(sd*g[1])**2])
            K=C@H.T@np.linalg.inv(H@C@H.T+S)
            out[i]=ah[i]-K@(H@ah[i])
    gt=np.c_[at[:,0]+at[:,1],at[:,2]+at[:,3]]
    g0=np.c_[ah[:,0]+ah[:,1],ah[:,2]+ah[:,3]]
    g1=np.c_[out[:,0]+out[:,1],out[:,2]+out[:,3]]
    e0=np.abs(g0/gt-1).ravel(); e1=np.abs(g1/gt-1).ravel()
    print(cond,'joint %.2f / %.2f %%  with prior %.2f / %.2f %%'%(100*e0.mean(),100*e0.max(),100*e1.mean(),100*e1.max()))
