#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# tools/research/multi-r5/rank2.py: offline analysis of docs/results/multi-vehicle.md
# "Round five" on the CSV rows of tools/research/amfi-multi (--loose); needs
# python3-numpy (scripts/install-deps.sh). An analysis, not a test.
# Join amfi-multi --loose runs at λ (A) and at --lambda-factor 0.1 (B, same
# draw): errors at λ, λ/10, λ/100 and candidate quality figures, ranked as the
# issue asks (largest tenth of errors in the worst tenth by the figure) and by
# Spearman's rho with |error|.
import csv,sys
import numpy as np
def load(f):
    d={}
    for r in csv.DictReader(l for l in open(f) if not l.startswith('#')):
        d[(r['sensors'],r['noise'],int(r['event']),r['vehicle'])]=r
    return d
A=load(sys.argv[1]); B=load(sys.argv[2])
def spear(a,b):
    ra=np.argsort(np.argsort(a)); rb=np.argsort(np.argsort(b)); return np.corrcoef(ra,rb)[0,1]
def hits(err,fig):
    n=len(err); d=max(1,n//10); top=set(np.argsort(-np.abs(err))[:d]); byf=np.argsort(-fig)[:d]
    return sum(1 for i in byf if i in top), d
for cond in [('1','0'),('1','0.02'),('3','0'),('3','0.02')]:
    ev=sorted(set(k[2] for k in B if k[:2]==cond and (cond+(k[2],'2')) in B))
    K=[cond+(e,v) for e in ev for v in '12']
    f=lambda D,key: np.array([float(D[k][key]) for k in K])
    truth=f(A,'truth_kg'); g1=f(A,'gvw_kg'); g10=f(B,'gvw_kg'); g100=f(B,'loose_axle1_kg')+f(B,'loose_axle2_kg')
    gl=f(A,'loose_axle1_kg')+f(A,'loose_axle2_kg')
    assert np.allclose(gl,g10,rtol=0,atol=0.5), 'the two runs differ'
    e1=g1/truth-1; e10=g10/truth-1; e100=g100/truth-1
    print('==',cond,'vehicles',len(K),'| error at λ %.2f/%.2f, λ/10 %.2f/%.2f, λ/100 %.2f/%.2f %%'%(
        100*np.abs(e1).mean(),100*np.abs(e1).max(),100*np.abs(e10).mean(),100*np.abs(e10).max(),100*np.abs(e100).mean(),100*np.abs(e100).max()))
    q1=f(A,'quality'); q10=f(B,'quality')
    figs={'λ→λ/10 (shipped)':q1,'λ/10→λ/100':q10,'λ→λ/100':np.abs(g100-g1)/g1,'sum of both steps':q1+q10}
    for name,err in (('errors at λ',e1),('errors at λ/10',e10)):
        print('  %s: '%name+' | '.join('%s %d/%d rho %.2f'%(k,*hits(err,v),spear(v,np.abs(err))) for k,v in figs.items()))
