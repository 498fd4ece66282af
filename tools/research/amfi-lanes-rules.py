#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# amfi-lanes-rules: docs/results/multi-vehicle.md "Two lanes", the rules tried: reads the
# CSVs of amfi-lanes-geometry (g2h3.csv: two lanes at 3 s, g2h6.csv: two lanes at 6 s,
# g1h3.csv: one lane at 3 s, in the current folder) and prints, per rule, the vehicles
# marked, the errors > 5 % caught, the fine ones marked and the kept ok vehicles' mean abs
# and worst error. Python 3 standard library only.
import csv
def rows(f):
    R = [r for r in csv.DictReader(open(f)) if r['status'] == 'ok' and r['err'] not in ('', 'None')]
    for r in R:
        r['e'] = abs(float(r['err'])); r['qq'] = float(r['q']) if r['q'] != 'None' else 1.0
        for k in ['f0.25','f0.5','f1','f1.5','f2','f3','mind']: r[k] = float(r[k])
        r['fo'] = r['foreign'] == '1'
    return R
sets = {k: rows(f) for k, f in [('2l3s', 'g2h3.csv'), ('2l6s', 'g2h6.csv'), ('1l3s', 'g1h3.csv')]}
def rule(R, pred):
    m = [r for r in R if pred(r)]
    big = sum(r['e'] > 5 for r in R)
    caught = sum(r['e'] > 5 for r in m)
    fine2 = sum(r['e'] <= 2 for r in m)
    keep = [r for r in R if not pred(r)]
    ke = [r['e'] for r in keep]
    return '%4d mk %3d/%3d fine%3d | kept %4d %.2f/%.1f >5:%d' % (len(m), caught, big, len(m) - caught, len(keep), sum(ke)/len(ke), max(ke), sum(x > 5 for x in ke))
c = []
for Q in [1.5, 2, 2.5, 3, 4, 5]:
    c.append(('q>%g' % Q, lambda r, Q=Q: r['qq'] > Q))
    c.append(('fo|q>%g' % Q, lambda r, Q=Q: r['fo'] or r['qq'] > Q))
    for d, F in [('f0.5', 0.3), ('f1', 0.3), ('f1', 0.5), ('f1.5', 0.5)]:
        c.append(('fo|%s>%g|q>%g' % (d, F, Q), lambda r, Q=Q, d=d, F=F: r['fo'] or r['qq'] > Q or r[d] > F))
for d, F in [('f0.5', 0.3), ('f1', 0.3), ('f1', 0.5), ('f1.5', 0.5)]:
    c.append(('fo|%s>%g' % (d, F), lambda r, d=d, F=F: r['fo'] or r[d] > F))
c.append(('fo', lambda r: r['fo']))
for n, p in c:
    print('%-22s' % n, '  ||  '.join(k + ' ' + rule(R, p) for k, R in sets.items()))
