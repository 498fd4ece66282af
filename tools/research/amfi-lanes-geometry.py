#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# amfi-lanes-geometry: docs/results/multi-vehicle.md "Two lanes": for each vehicle of
# amfid stores (sqlite3, the passages and passage_errors of a simulated stream), its GVW
# error, quality and the geometry of its axles against the other vehicles' axles on the
# span (share of its crossing with an axle within 0.25 .. 3 m of another's, the closest
# distance, and whether a vehicle outside its solve was on the span in its window), one
# CSV row a vehicle. Python 3 standard library only. An analysis, not a test.
#   amfi-lanes-geometry OUT.csv STORE.db [STORE.db ...]
"""Per vehicle of an amfid store: GVW error against truth, quality, n_vehicles,
and the geometry of its axles against other vehicles' axles on the span."""
import sqlite3, sys, math
L = 20.0
DT = 0.002
D0S = [0.25, 0.5, 1.0, 1.5, 2.0, 3.0]

def load(db):
    c = sqlite3.connect(db)
    rows = c.execute("""select p.id, p.vehicle_id, p.utime, p.lane, p.speed_given_mps, p.n_axles,
        p.status, p.n_vehicles, p.quality, e.gvw_error_pct, p.gvw_kg, e.true_gvw_kg
        from passages p left join passage_errors e on e.passage_id = p.id order by p.id""").fetchall()
    veh = []
    for r in rows:
        sp = [x[0] for x in c.execute("select spacing_m from axles where passage_id=? and idx>1 order by idx", (r[0],))]
        off = [0.0]
        for s in sp: off.append(off[-1] + s)
        veh.append(dict(id=r[1], t0=r[2] * 1e-6, lane=r[3], v=r[4], off=off, status=r[6], nv=r[7],
                        q=r[8], err=r[9], gvw=r[10], true=r[11]))
    return veh

def geometry(veh):
    k = 0; ev = 0
    while k < len(veh):
        n = max(1, veh[k]['nv']) if veh[k]['status'] == 'ok' else 1
        for m in range(k, min(k + n, len(veh))): veh[m]['ev'] = ev
        ev += 1; k += n
    for a in veh:
        a['tin'] = a['t0']; a['tout'] = a['t0'] + (L + a['off'][-1]) / a['v']
    for i, a in enumerate(veh):
        best = {d: (0.0, None) for d in D0S}
        mind = math.inf
        T = a['tout'] - a['tin']
        for j, b in enumerate(veh):
            if j == i or b['tout'] <= a['tin'] or b['tin'] >= a['tout']:
                continue
            t = max(a['tin'], b['tin']); t1 = min(a['tout'], b['tout'])
            cnt = {d: 0 for d in D0S}
            while t < t1:
                xa = [a['v'] * (t - a['t0']) - o for o in a['off']]
                xb = [b['v'] * (t - b['t0']) - o for o in b['off']]
                xa = [x for x in xa if 0 <= x <= L]; xb = [x for x in xb if 0 <= x <= L]
                if xa and xb:
                    dm = min(abs(p - q) for p in xa for q in xb)
                    mind = min(mind, dm)
                    for d in D0S:
                        if dm < d: cnt[d] += 1
                t += DT
            for d in D0S:
                f = cnt[d] * DT / T
                if f > best[d][0]: best[d] = (f, b['id'])
        a['mind'] = mind
        a['foreign'] = 0
        for b in veh:
            if b is not a and b['ev'] != a['ev'] and b['tin'] < a['tout'] + 0.05 and b['tout'] > a['tin'] - 0.35:
                a['foreign'] = 1
        a['frac'] = {d: best[d][0] for d in D0S}
        a['with'] = {d: best[d][1] for d in D0S}
    return veh

if __name__ == '__main__':
    out = open(sys.argv[1], 'w')
    out.write('run,id,lane,nv,status,q,err,foreign,mind,' + ','.join('f%g' % d for d in D0S) + '\n')
    for db in sys.argv[2:]:
        veh = geometry(load(db))
        for a in veh:
            out.write('%s,%d,%d,%d,%s,%s,%s,%d,%s,%s\n' % (db, a['id'], a['lane'], a['nv'], a['status'],
                      a['q'], a['err'], a['foreign'], a['mind'], ','.join('%.4f' % a['frac'][d] for d in D0S)))
