#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# tools/research/multi-r5/extrap.py: offline analysis of docs/results/multi-vehicle.md
# "Round five" on the CSV rows of tools/research/amfi-multi (--loose); needs
# python3-numpy (scripts/install-deps.sh). An analysis, not a test.
# GVW errors of tight + t*(loose - tight) per condition: t = 0 the shipped
# solve (λ), t = 1 the solve at λ/10, t > 1 extrapolated further.
import csv,sys
import numpy as np
rows=[r for r in csv.DictReader(l for l in open(sys.argv[1]) if not l.startswith('#'))]
for cond in [('1','0'),('1','0.02'),('3','0'),('3','0.02')]:
    rr=[r for r in rows if (r['sensors'],r['noise'])==cond]
    ev={}
    for r in rr: ev.setdefault(int(r['event']),{})[r['vehicle']]=r
    E=sorted(e for e in ev if len(ev[e])==2)
    g=lambda key: np.array([[float(ev[e][v][key%k]) for v in '12' for k in (1,2)] for e in E])
    ah=g('axle%d_kg'); at=g('truth_axle%d_kg'); al=g('loose_axle%d_kg')
    V=lambda x: np.c_[x[:,0]+x[:,1],x[:,2]+x[:,3]]
    gt=V(at); out=[]
    for t in (0,0.5,1,1.5,2,3):
        e=(V(ah+t*(al-ah))/gt-1).ravel(); s=((V(ah+t*(al-ah)).sum(1))/gt.sum(1)-1)
        out.append('t=%g %.2f/%.2f (sum %.2f/%.2f)'%(t,100*np.abs(e).mean(),100*np.abs(e).max(),100*np.abs(s).mean(),100*np.abs(s).max()))
    print(cond,len(E),' | '.join(out))
