#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# tools/research/multi-r5/gapsplit.py: offline analysis of docs/results/multi-vehicle.md
# "Round five" on the CSV rows of tools/research/amfi-multi (--loose); needs
# python3-numpy (scripts/install-deps.sh). An analysis, not a test.
# errors at λ and at λ/10 (the loose columns) by the gap: under 1 m, 1-3 m, 3 m and more
import csv,sys
import numpy as np
rows=[r for r in csv.DictReader(l for l in open(sys.argv[1]) if not l.startswith('#'))]
for cond in [('1','0'),('1','0.02'),('3','0'),('3','0.02')]:
    rr=[r for r in rows if (r['sensors'],r['noise'])==cond]
    out=[]
    for lo,hi in ((-99,1),(1,3),(3,99)):
        s=[r for r in rr if lo<=float(r['gap_m'])<hi]
        if not s: continue
        t=np.array([float(r['truth_kg']) for r in s]); g=np.array([float(r['gvw_kg']) for r in s])
        l=np.array([float(r['loose_axle1_kg'])+float(r['loose_axle2_kg']) for r in s])
        e0=np.abs(g/t-1); e1=np.abs(l/t-1)
        out.append('gap %g..%g m (%d): %.2f/%.2f -> %.2f/%.2f'%(lo,hi,len(s),100*e0.mean(),100*e0.max(),100*e1.mean(),100*e1.max()))
    print(cond,' | '.join(out))
