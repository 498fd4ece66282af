#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# tools/research/multi-r5/loose.py: offline analysis of docs/results/multi-vehicle.md
# "Round five" on the CSV rows of tools/research/amfi-multi (--loose); needs
# python3-numpy (scripts/install-deps.sh). An analysis, not a test.
# Round five, offline on amfi-multi --loose rows: (1) how much of each event's
# axle-load error lies along the direction the data leave open (loose - tight
# solve, d); (2) the signed relation of the GVW error to the GVW change along d;
# (3) a front-share prior applied along d (t*d, t ~ N(0, tau^2)); (4) figures.
import csv,sys
import numpy as np
f=sys.argv[1]; mu=float(sys.argv[2]) if len(sys.argv)>2 else 0.475; sd=float(sys.argv[3]) if len(sys.argv)>3 else 0.072
rows=[r for r in csv.DictReader(l for l in open(f) if not l.startswith('#'))]
def spear(a,b):
    ra=np.argsort(np.argsort(a)); rb=np.argsort(np.argsort(b)); return np.corrcoef(ra,rb)[0,1]
def hits(err,fig):
    n=len(err); d=max(1,n//10); top=set(np.argsort(-np.abs(err))[:d]); byf=np.argsort(-fig)[:d]
    return sum(1 for i in byf if i in top), d
for cond in [('1','0'),('1','0.02'),('3','0'),('3','0.02')]:
    rr=[r for r in rows if (r['sensors'],r['noise'])==cond]
    ev={}
    for r in rr: ev.setdefault(int(r['event']),{})[r['vehicle']]=r
    E=sorted(ev)
    g=lambda key: np.array([[float(ev[e][v][key%k]) for v in '12' for k in (1,2)] for e in E])
    ah=g('axle%d_kg'); at=g('truth_axle%d_kg'); al=g('loose_axle%d_kg')
    q=np.array([[float(ev[e][v]['quality']) for v in '12'] for e in E])
    ms=np.array([float(ev[e]['1']['solve_ms']) for e in E]); lms=np.array([float(ev[e]['1']['loose_ms']) for e in E])
    e_=ah-at; d=al-ah
    V=lambda x: np.c_[x[:,0]+x[:,1],x[:,2]+x[:,3]]
    gt,gh,gl=V(at),V(ah),V(al)
    err=(gh/gt-1).ravel(); dg=((gl-gh)/gh).ravel()
    # (1) share of the axle error's energy along d
    cos=np.array([abs(e_[i]@d[i])/(np.linalg.norm(e_[i])*np.linalg.norm(d[i])+1e-9) for i in range(len(E))])
    big=np.argsort(-np.abs(err.reshape(-1,2)).max(1))[:max(1,len(E)//10)]
    # per-vehicle: error along d (projection) vs the rest
    proj=np.array([(e_[i]@d[i])/(d[i]@d[i]+1e-9) for i in range(len(E))])   # e ~ proj*d
    e_along=V(proj[:,None]*d)/gt; 
    print('==',cond,'events',len(E),'solve %.0f ms, loose solve %.0f ms (median)'%(np.median(ms),np.median(lms)))
    print('  |cos(error, d)| median %.2f, in the worst tenth of events %.2f; error along d explains %.0f %% of the GVW error energy (worst tenth %.0f %%)'%(
        np.median(cos),np.median(cos[big]),100*np.sum(e_along.ravel()**2)/np.sum(err**2),100*np.sum(e_along[big].ravel()**2)/np.sum(err.reshape(-1,2)[big].ravel()**2)))
    print('  error along d in units of d (t with error = t d): median %.2f, IQR %.2f..%.2f'%(np.median(proj),*np.percentile(proj,[25,75])))
    print('  signed corr(GVW error, GVW change at lambda/10) %.2f; rho(|err|,|change|) %.2f'%(np.corrcoef(err,dg)[0,1],spear(np.abs(err),np.abs(dg))))
    # (3) prior along d: t minimises t^2/tau^2 + sum_v (h_v.(a+t d))^2/(sd g_v)^2
    def apply(tau, muv=None):
        out=np.zeros_like(ah)
        for i in range(len(E)):
            m=[mu,mu] if muv is None else muv[i]
            H=np.array([[1-m[0],-m[0],0,0],[0,0,1-m[1],-m[1]]]); w=1/(sd*gh[i])**2
            r0=H@ah[i]; hd=H@d[i]
            t=-np.sum(w*r0*hd)/(1/tau**2+np.sum(w*hd*hd))
            out[i]=ah[i]+t*d[i]
        return (V(out)/gt-1).ravel()
    for tau in (0.5,1,2,4):
        ep=apply(tau); print('  prior mean %.3f sd %.3f along d, tau %.1f: %.2f / %.2f %% (joint %.2f / %.2f %%)'%(mu,sd,tau,100*np.abs(ep).mean(),100*np.abs(ep).max(),100*np.abs(err).mean(),100*np.abs(err).max()))
    tm=np.array([[at[i][0]/gt[i][0],at[i][2]/gt[i][1]] for i in range(len(E))])
    ep=apply(2,tm); print('  the TRUE split as prior (sd %.3f) along d, tau 2: %.2f / %.2f %%'%(sd,100*np.abs(ep).mean(),100*np.abs(ep).max()))
    # (4) figures
    light=np.c_[gh[:,1]/gh[:,0],gh[:,0]/gh[:,1]].ravel()
    dn=np.repeat(np.linalg.norm(d,axis=1),2)/V(ah).ravel()
    figs={'quality (shipped)':q.ravel(),'|d| axle-norm / gvw':dn,'quality*other/own':q.ravel()*light,
          'quality+|d|':np.argsort(np.argsort(q.ravel()))+np.argsort(np.argsort(dn))}
    print('  '+' | '.join('%s %d/%d rho %.2f'%(k,*hits(err,v),spear(v,np.abs(err))) for k,v in figs.items()))
