-- SPDX-License-Identifier: GPL-3.0-or-later
-- report_classes fixture: 40 passages 10 minutes apart from 2025-11-22
-- 00:00 UTC in four classes as amfid stores them (passages.class,
-- axle_groups, overload; store version 10), on two lanes: A23 (tractor with
-- a tridem semi-trailer, one of them overloaded: 46 t, its tridem 27.6 t),
-- R3 (rigid with a tandem), R2 and CAR; one passage a gap.
WITH RECURSIVE k(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM k WHERE i < 40),
c(i, cls, n, gvw) AS (
  SELECT i, CASE i % 4 WHEN 0 THEN 'A23' WHEN 1 THEN 'R3' WHEN 2 THEN 'R2' ELSE 'CAR' END,
         CASE i % 4 WHEN 0 THEN 5 WHEN 1 THEN 3 ELSE 2 END,
         CASE WHEN i = 8 THEN 46000.0
              WHEN i % 4 = 0 THEN 28000.0 + 1000 * (i % 7)
              WHEN i % 4 = 1 THEN 18000.0 + 500 * (i % 5)
              WHEN i % 4 = 2 THEN 10000.0 + 250 * (i % 6)
              ELSE 1200.0 + 100 * (i % 3) END
  FROM k)
INSERT INTO passages (id, vehicle_id, utime, lane, speed_mps, n_axles, gvw_kg, status, reason,
                      lambda, residual_rms, formulation, solve_ms, speed_given_mps,
                      speed_estimated, n_vehicles, quality, class, axle_groups, overload)
SELECT i, 1000 + i, 1763769600000000 + i * 600000000, 1 + (i / 4) % 2, 24.0, n,
       CASE WHEN i = 39 THEN NULL ELSE gvw END,
       CASE WHEN i = 39 THEN 'gap' ELSE 'ok' END, CASE WHEN i = 39 THEN 'samples missing' ELSE '' END,
       1e-8, 0.001 * (1 + i % 3), 'paper', 10.0, 24.0, 0, 1, 1.5, cls,
       CASE cls WHEN 'A23' THEN '1-1-3' WHEN 'R3' THEN '1-2' ELSE '1-1' END,
       CASE WHEN i = 39 THEN NULL WHEN i = 8 THEN 1 ELSE 0 END
FROM c;
-- the axles: spacings and load shares of each class
CREATE TEMP TABLE shape (cls TEXT, idx INTEGER, spacing_m REAL, share REAL);
INSERT INTO shape VALUES
  ('A23', 1, NULL, 0.15), ('A23', 2, 3.6, 0.25), ('A23', 3, 6.0, 0.2), ('A23', 4, 1.3, 0.2),
  ('A23', 5, 1.3, 0.2),
  ('R3', 1, NULL, 0.3), ('R3', 2, 4.5, 0.35), ('R3', 3, 1.35, 0.35),
  ('R2', 1, NULL, 0.4), ('R2', 2, 4.5, 0.6),
  ('CAR', 1, NULL, 0.5), ('CAR', 2, 2.6, 0.5);
INSERT INTO axles (passage_id, idx, spacing_m, load_kg)
SELECT p.id, s.idx, s.spacing_m, CASE WHEN p.gvw_kg IS NULL THEN NULL ELSE s.share * p.gvw_kg END
FROM passages p JOIN shape s ON s.cls = p.class;
INSERT INTO meta (key, value) VALUES ('site.id', 'classes-test');
