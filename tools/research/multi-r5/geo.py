#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# tools/research/multi-r5/geo.py: offline analysis of docs/results/multi-vehicle.md
# "Round five" on the CSV rows of tools/research/amfi-multi (--loose); needs
# python3-numpy (scripts/install-deps.sh). An analysis, not a test.
# Geometric candidate figures from amfi-multi's CSV (L = 20 m), ranked as the
# issue asks: hits of the largest-decile errors in the worst decile by figure,
# and Spearman's rho with |error|.
import csv,sys,math
import numpy as np
L=20.0
def spear(a,b):
    ra=np.argsort(np.argsort(a)); rb=np.argsort(np.argsort(b))
    return np.corrcoef(ra,rb)[0,1]
def hits(err,fig):
    n=len(err); d=max(1,n//10)
    top=set(np.argsort(-np.abs(err))[:d]); byf=np.argsort(-fig)[:d]
    return sum(1 for i in byf if i in top), d
rows=[r for r in csv.DictReader(l for l in open(sys.argv[1]) if not l.startswith('#'))]
for cond in [('1','0'),('1','0.02'),('3','0'),('3','0.02')]:
    rr=[r for r in rows if (r['sensors'],r['noise'])==cond]
    ev={}
    for r in rr: ev.setdefault(int(r['event']),{})[r['vehicle']]=r
    F={}; err=[]
    def add(k,x): F.setdefault(k,[]).append(x)
    for e in sorted(ev):
        a,b=ev[e]['1'],ev[e]['2']
        v=float(a['speed_mps']); s0=float(a['spacing_m']); s1=float(b['spacing_m']); g=float(a['gap_m'])
        c=[0,s0,s0+g,s0+g+s1]   # axle offsets behind the leader's front axle
        veh=[0,0,1,1]
        t=np.arange(0,(L+c[3])/v,1e-3); x=np.array([v*t-ci for ci in c])  # 4 x T
        on=(x>=0)&(x<=L)
        sn=np.where(on,np.sin(np.pi*np.clip(x,0,L)/L),0)
        for i,r in ((0,a),(1,b)):
            err.append(float(r['err']))
            mine=[k for k in range(4) if veh[k]==i]; oth=[k for k in range(4) if veh[k]!=i]
            both=on[mine].any(0)&on[oth].any(0)
            # mirror: my axle at x, another at L-x within 1 m, sensitivity-weighted
            mir=0; cnt=0; near=0; amb=0
            for p in mine:
                for q in oth:
                    m=on[p]&on[q]
                    mir+=np.sum(m*(np.abs(x[p]+x[q]-L)<1.0)*sn[p])
                    cnt+=np.sum(m*(np.abs(x[p]-x[q])<1.0))
                # my axle poorly seen (near a support) while the other vehicle loads the span
                near+=np.sum(on[p]&both[None,:].ravel()*(sn[p]<0.5))/max(1,on[p].sum())
            # ambiguity: mean over my on-span time of the other vehicle's sensitivity share
            S=sn.sum(0)+1e-9; mys=sn[mine].sum(0); ots=sn[oth].sum(0)
            m1=on[mine].any(0)
            amb=np.sum((ots/S)[m1])/m1.sum()
            add('mirror',mir); add('near_support',near); add('other_share',amb)
            add('shared',float(r['shared'])); add('-|gap-L/2|',-abs(g-L/2)); add('-gap',-g)
            add('quality',float(r['quality'])); add('leader',1.0-i)
            # my weight over the pair's weight (estimated): light vehicles err more in %
            add('light',float(ev[e]['2' if i==0 else '1']['gvw_kg'])/float(r['gvw_kg']))
            add('q*light',float(r['quality'])*float(ev[e]['2' if i==0 else '1']['gvw_kg'])/float(r['gvw_kg']))
    err=np.array(err)
    print(cond, ' | '.join('%s %d/%d rho %.2f'%(k,*hits(err,np.array(f)),spear(np.array(f),np.abs(err))) for k,f in F.items()))
