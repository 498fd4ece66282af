-- SPDX-License-Identifier: GPL-3.0-or-later
-- report_golden fixture: every section of amfi-report has rows (values chosen
-- so that their statistics are exact in binary floating point).
-- 48 passages half an hour apart from 2025-11-22 00:00 UTC, lanes 1 and 2;
-- every eighth a gap, one invalid; ok GVW 16 000 + 1000·(i mod 5) kg, one
-- overloaded (46 000 kg); estimated speeds on lane 2.
WITH RECURSIVE k(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM k WHERE i < 48)
INSERT INTO passages (id, vehicle_id, utime, lane, speed_mps, n_axles, gvw_kg, status, reason,
                      lambda, residual_rms, formulation, solve_ms, speed_given_mps,
                      speed_estimated, n_vehicles, quality)
SELECT i, 100 + i, 1763769600000000 + i * 1800000000, 1 + i % 2,
       CASE WHEN i % 8 = 0 THEN NULL ELSE 24.0 + 0.25 * (i % 4) END,
       CASE WHEN i % 8 = 0 THEN 0 ELSE 3 END,
       CASE WHEN i % 8 = 0 THEN NULL WHEN i = 13 THEN 46000.0 ELSE 16000.0 + 1000 * (i % 5) END,
       CASE WHEN i % 8 = 0 THEN 'gap' WHEN i = 27 THEN 'invalid' ELSE 'ok' END,
       CASE WHEN i % 8 = 0 THEN '=HYPERLINK("x"), 12 samples missing' WHEN i = 27 THEN 'axle spacing "odd", refused' ELSE '' END,
       7.5e-9, 0.001, 'paper', 12.5,
       CASE WHEN i % 8 = 0 THEN NULL WHEN i % 2 = 0 THEN 24.0 ELSE 24.0 + 0.25 * (i % 4) END,
       CASE WHEN i % 2 = 0 AND i % 8 <> 0 THEN 1 ELSE 0 END,
       CASE WHEN i = 31 THEN 2 ELSE 1 END,
       CASE WHEN i % 8 = 0 THEN NULL ELSE 1.5 END
FROM k;
UPDATE passages SET f1_hz = 5.5 + 0.125 * (vehicle_id % 3), f1_zeta = 0.03125, f1_r2 = 0.875,
       f1_comp_hz = CASE WHEN vehicle_id > 120 THEN 5.75 END
WHERE status = 'ok';
UPDATE passages SET gvw_comp_kg = gvw_kg + 250 WHERE status = 'ok' AND lane = 2;
-- the class and groups of version 10 (the three-axle rows: a rigid steer + tandem), one
-- hostile class text; rows before the migration keep NULL
UPDATE passages SET class = 'R3', axle_groups = '1-2',
  overload = CASE WHEN gvw_kg IS NULL THEN NULL ELSE gvw_kg > 26000 END WHERE n_axles = 3;
UPDATE passages SET class = '=cmd|"x",y' WHERE id = (SELECT max(id) FROM passages WHERE n_axles = 3);
INSERT INTO axles (passage_id, idx, spacing_m, load_kg)
SELECT id, 1, NULL, 0.25 * gvw_kg FROM passages WHERE n_axles = 3;
INSERT INTO axles (passage_id, idx, spacing_m, load_kg)
SELECT id, 2, 4.5, 0.375 * gvw_kg FROM passages WHERE n_axles = 3;
INSERT INTO axles (passage_id, idx, spacing_m, load_kg)
SELECT id, 3, 1.25, CASE WHEN id = 27 THEN NULL ELSE 0.375 * gvw_kg END FROM passages WHERE n_axles = 3;
INSERT INTO truth (vehicle_id, utime, gvw_kg, n_axles, speed_true_mps)
SELECT vehicle_id, utime, coalesce(gvw_kg, 16000.0) / 1.25, 3, 24.0 FROM passages;
INSERT INTO truth_axles (truth_id, idx, load_kg, mean_force_N)
SELECT id, 1, gvw_kg, NULL FROM truth;
INSERT INTO baseline (utime_set, n, mean_kg, std_kg, source, note)
VALUES (1763769600000000, 30, 18000, 1500, 'auto', ''),
       (1763780400000000, 12, 18000, 1250, 'manual', 'after, the "repair"');
WITH RECURSIVE k(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM k WHERE i < 24)
INSERT INTO indicators (utime, n, mean_kg, std_kg, baseline_mean_kg, baseline_std_kg,
                        std_ratio, p_value, state)
SELECT 1763769600000000 + i * 3600000000, 16, 18000 + 8 * i, 1250 + 25 * i, 18000, 1250,
       (1250 + 25 * i) / 1250.0, 0.5 / i, CASE WHEN i >= 20 THEN 'alert' ELSE 'normal' END
FROM k;
INSERT INTO alerts (utime, level, kind, message, indicator_id, raised) VALUES
  (1763769600000000 + 10 * 3600000000, 'info', 'mean_shift', '+6 % over, the "baseline"', 10, 1),
  (1763769600000000 + 12 * 3600000000, 'info', 'mean_shift', 'back within 3 %', 12, 0),
  (1763769600000000 + 20 * 3600000000, 'warning', 'std_increase', '@SUM(A1) STD 1.4 x
baseline', 20, 1),
  (1763769600000000 + 21 * 3600000000, 'warning', 'scale_shift', 'scale 1.0625', NULL, 1);
WITH RECURSIVE k(i) AS (SELECT 0 UNION ALL SELECT i + 1 FROM k WHERE i < 11)
INSERT INTO environment (utime, deck_c, air_c, received_utime)
SELECT 1763769600000000 + i * 7200000000, -3.25 + i, -6.0 + 0.5 * i, 1763769600000000 FROM k;
INSERT INTO scale_evals (utime, kind, n, value, raw, deck_c, z, cusum, h, state) VALUES
  (1763773200000000, 'scale_shift', 20, 1.0, 1.0, 4.5, NULL, 0, 5, 'baseline'),
  (1763780400000000, 'scale_shift', 10, 1.0078125, 1.015625, 2.5, 0.5, 0.25, 5, 'normal'),
  (1763787600000000, 'scale_shift', 10, 1.03125, 1.046875, 1.5, 2.5, 2.75, 5, 'watch'),
  (1763794800000000, 'scale_shift', 10, 1.0625, 1.078125, 0.5, 4.5, 6.25, 5, 'alert'),
  (1763776800000000, 'known_truck', 1, 0.984375, 0.9921875, 3.5, NULL, NULL, NULL, 'normal'),
  (1763798400000000, 'known_truck', 2, 1.015625, 1.0234375, 1.0, 1.5, 0.5, 4, 'normal');
INSERT INTO meta (key, value) VALUES ('site.id', 'A23-north'), ('site.name', 'A23 bridge, north'),
  ('intake.run', '3'), ('intake.messages_received', '12345'), ('intake.messages_refused', '2'),
  ('intake.datagrams_dropped', '0'), ('intake.samples_missing', '17'),
  ('intake.passages_lost', '1'), ('intake.as_of', '2025-11-23T00:00:00Z'),
  ('natfreq.short', '3'), ('natfreq.noisy', '1');
