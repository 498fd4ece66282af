/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_schema.c: the store's schema as SQL, and the ordered list of
 * migrations that builds it from an empty file (store_open.c applies them).
 * A step, once released, is never edited: a change is a new step. The
 * final schema is exactly the DDL in docs/schema.md (tests/store/test_store.c
 * compares the two). No state, no threads.
 */
#include "store_internal.h"

/* The schema's CHECK constraints spell these numbers out. */
_Static_assert(AMFI_MAX_AXLES == 12,
               "schema v1 checks idx/n_axles against 12: add a migration");
_Static_assert(AMFI_STORE_APPLICATION_ID == 1095583305,
               "schema v1 sets PRAGMA application_id = 1095583305");

/* ---- schema --------------------------------------------------------------- */

/* Version 1, exactly as docs/schema.md shows it (tests/store/test_store.c compares
 * the two). The comments inside CREATE statements are kept by SQLite, so
 * `sqlite3 DB .schema passages` shows units and meanings. */
static const char schema_v1[] =
    "PRAGMA application_id = 1095583305;\n"
    "\n"
    "CREATE TABLE schema_migrations (\n"
    "  version     INTEGER PRIMARY KEY,  -- PRAGMA user_version once this step is applied\n"
    "  description TEXT NOT NULL,\n"
    "  applied_at  TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))  -- wall clock, UTC\n"
    ") STRICT;\n"
    "\n"
    "CREATE TABLE passages (\n"
    "  id           INTEGER PRIMARY KEY,  -- passage_id of the AMFI_PASSAGE message\n"
    "  vehicle_id   INTEGER NOT NULL,     -- from the vehicle detector (AMFI_VEHICLE)\n"
    "  utime        INTEGER NOT NULL      -- data time the first axle reaches x = 0, µs since 1970 UTC\n"
    "               CHECK (utime BETWEEN 0 AND 253402300799999999),\n"
    "  lane         INTEGER NOT NULL CHECK (lane BETWEEN -32768 AND 32767),\n"
    "  speed_mps    REAL CHECK (speed_mps BETWEEN 0 AND 150),    -- m/s; NULL unknown\n"
    "  n_axles      INTEGER NOT NULL CHECK (n_axles BETWEEN 0 AND 12),  -- rows in axles; 0 unknown\n"
    "  gvw_kg       REAL CHECK (gvw_kg BETWEEN -1e6 AND 1e6),    -- inferred GVW, kg; NULL not solved\n"
    "  status       TEXT NOT NULL CHECK (status IN\n"
    "                 ('ok', 'gap', 'late', 'overload', 'multiple', 'invalid', 'error')),\n"
    "  reason       TEXT NOT NULL DEFAULT '',                    -- why not ok; '' when ok\n"
    "  lambda       REAL CHECK (lambda > 0),                     -- λ at the reference rate\n"
    "  residual_rms REAL CHECK (residual_rms >= 0),              -- fit residual RMS, m/s²\n"
    "  formulation  TEXT CHECK (length(formulation) BETWEEN 1 AND 63),  -- solver output equation\n"
    "  solve_ms     REAL CHECK (solve_ms >= 0),                  -- solver wall time, ms\n"
    "  stored_at    TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),  -- wall clock, UTC\n"
    "  CHECK (status <> 'ok' OR (gvw_kg > 0 AND speed_mps > 0 AND n_axles >= 1))\n"
    ") STRICT;\n"
    "CREATE INDEX passages_utime ON passages (utime);\n"
    "CREATE INDEX passages_status_utime ON passages (status, utime);\n"
    "CREATE INDEX passages_vehicle ON passages (vehicle_id);\n"
    "\n"
    "CREATE TABLE axles (\n"
    "  passage_id INTEGER NOT NULL REFERENCES passages (id) ON DELETE CASCADE,\n"
    "  idx        INTEGER NOT NULL CHECK (idx BETWEEN 1 AND 12),  -- 1 = front axle\n"
    "  spacing_m  REAL CHECK (spacing_m > 0 AND spacing_m <= 50), -- to axle idx - 1, m; NULL for idx 1\n"
    "  load_kg    REAL CHECK (load_kg BETWEEN -1e6 AND 1e6),      -- inferred axle load, kg; NULL not solved\n"
    "  PRIMARY KEY (passage_id, idx),\n"
    "  CHECK (idx > 1 OR spacing_m IS NULL)\n"
    ") STRICT, WITHOUT ROWID;\n"
    "\n"
    "CREATE TABLE truth (\n"
    "  id             INTEGER PRIMARY KEY,\n"
    "  vehicle_id     INTEGER NOT NULL,  -- as passages.vehicle_id\n"
    "  utime          INTEGER NOT NULL   -- as passages.utime, µs\n"
    "                 CHECK (utime BETWEEN 0 AND 253402300799999999),\n"
    "  gvw_kg         REAL NOT NULL CHECK (gvw_kg > 0 AND gvw_kg <= 1e6),  -- true GVW, kg\n"
    "  n_axles        INTEGER NOT NULL CHECK (n_axles BETWEEN 1 AND 12),   -- rows in truth_axles\n"
    "  speed_true_mps REAL CHECK (speed_true_mps > 0 AND speed_true_mps <= 150)  -- m/s; NULL unknown\n"
    ") STRICT;\n"
    "CREATE INDEX truth_vehicle ON truth (vehicle_id, utime);\n"
    "\n"
    "CREATE TABLE truth_axles (\n"
    "  truth_id     INTEGER NOT NULL REFERENCES truth (id) ON DELETE CASCADE,\n"
    "  idx          INTEGER NOT NULL CHECK (idx BETWEEN 1 AND 12),  -- 1 = front axle\n"
    "  load_kg      REAL NOT NULL CHECK (load_kg > 0 AND load_kg <= 1e6),  -- static axle load, kg\n"
    "  mean_force_N REAL CHECK (mean_force_N BETWEEN -1e7 AND 1e7),  -- mean contact force on the span, N\n"
    "  PRIMARY KEY (truth_id, idx)\n"
    ") STRICT, WITHOUT ROWID;\n"
    "\n"
    "CREATE TABLE indicators (\n"
    "  id               INTEGER PRIMARY KEY,  -- indicator_id of the AMFI_INDICATOR message\n"
    "  utime            INTEGER NOT NULL      -- data time of the newest passage in the window, µs\n"
    "                   CHECK (utime BETWEEN 0 AND 253402300799999999),\n"
    "  n                INTEGER NOT NULL CHECK (n >= 0),                 -- ok passages in the window\n"
    "  mean_kg          REAL CHECK (mean_kg BETWEEN -1e6 AND 1e6),       -- window mean GVW, kg\n"
    "  std_kg           REAL CHECK (std_kg BETWEEN 0 AND 1e6),           -- window STD of GVW, kg\n"
    "  baseline_mean_kg REAL CHECK (baseline_mean_kg > 0 AND baseline_mean_kg <= 1e6),  -- kg\n"
    "  baseline_std_kg  REAL CHECK (baseline_std_kg > 0 AND baseline_std_kg <= 1e6),    -- kg\n"
    "  std_ratio        REAL CHECK (std_ratio BETWEEN 0 AND 1e6),        -- std_kg / baseline_std_kg\n"
    "  p_value          REAL CHECK (p_value BETWEEN 0 AND 1),  -- one-sided variance-ratio test\n"
    "  state            TEXT NOT NULL CHECK (state IN ('baseline', 'normal', 'watch', 'alert'))\n"
    ") STRICT;\n"
    "CREATE INDEX indicators_utime ON indicators (utime);\n"
    "\n"
    "CREATE TABLE alerts (\n"
    "  id           INTEGER PRIMARY KEY,  -- alert_id of the AMFI_ALERT message\n"
    "  utime        INTEGER NOT NULL      -- data time, µs\n"
    "               CHECK (utime BETWEEN 0 AND 253402300799999999),\n"
    "  level        TEXT NOT NULL CHECK (level IN ('info', 'warning')),\n"
    "  kind         TEXT NOT NULL CHECK (length(kind) BETWEEN 1 AND 31),  -- std_increase, mean_shift, ...\n"
    "  message      TEXT NOT NULL,\n"
    "  indicator_id INTEGER REFERENCES indicators (id),  -- the indicator behind it; NULL none\n"
    "  raised       INTEGER NOT NULL CHECK (raised IN (0, 1))  -- 1 raised, 0 cleared\n"
    ") STRICT;\n"
    "CREATE INDEX alerts_utime ON alerts (utime);\n"
    "CREATE INDEX alerts_indicator ON alerts (indicator_id);\n"
    "\n"
    "CREATE TABLE baseline (\n"
    "  id        INTEGER PRIMARY KEY,  -- the newest row is the baseline in force\n"
    "  utime_set INTEGER NOT NULL      -- data time from which it applies, µs\n"
    "            CHECK (utime_set BETWEEN 0 AND 253402300799999999),\n"
    "  n         INTEGER NOT NULL CHECK (n >= 2),                        -- ok passages behind it\n"
    "  mean_kg   REAL NOT NULL CHECK (mean_kg > 0 AND mean_kg <= 1e6),  -- healthy mean GVW, kg\n"
    "  std_kg    REAL NOT NULL CHECK (std_kg > 0 AND std_kg <= 1e6),    -- healthy STD of GVW, kg\n"
    "  source    TEXT NOT NULL CHECK (source IN ('auto', 'manual')),\n"
    "  note      TEXT NOT NULL DEFAULT '' CHECK (length(CAST(note AS BLOB)) <= 127),\n"
    "  set_at    TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))  -- wall clock, UTC\n"
    ") STRICT;\n"
    "\n"
    "CREATE TABLE meta (\n"
    "  key        TEXT NOT NULL PRIMARY KEY CHECK (length(key) BETWEEN 1 AND 63),\n"
    "  value      TEXT NOT NULL CHECK (length(CAST(value AS BLOB)) <= 4096),\n"
    "  updated_at TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))  -- wall clock, UTC\n"
    ") STRICT;\n"
    "\n"
    "CREATE VIEW daily_trend AS\n"
    "WITH d AS (\n"
    "  SELECT date(utime / 1000000, 'unixepoch') AS day, status, gvw_kg FROM passages\n"
    "), m AS (\n"
    "  SELECT day, avg(gvw_kg) AS mean_kg FROM d WHERE status = 'ok' GROUP BY day\n"
    ")\n"
    "SELECT d.day AS day,                          -- UTC date of utime\n"
    "       sum(d.status = 'ok') AS n_ok,\n"
    "       m.mean_kg AS mean_kg,                  -- mean GVW of the ok passages, kg\n"
    "       CASE WHEN sum(d.status = 'ok') > 1 THEN\n"
    "         sqrt(sum(CASE WHEN d.status = 'ok' THEN (d.gvw_kg - m.mean_kg) * (d.gvw_kg - m.mean_kg) END)\n"
    "              / (sum(d.status = 'ok') - 1))\n"
    "       END AS std_kg,                         -- their sample STD, kg\n"
    "       sum(d.status <> 'ok') AS n_not_ok\n"
    "FROM d LEFT JOIN m ON m.day = d.day\n"
    "GROUP BY d.day\n"
    "ORDER BY d.day;\n"
    "\n"
    "CREATE VIEW window_trend AS\n"
    "SELECT i.id AS indicator_id, i.utime, datetime(i.utime / 1000000, 'unixepoch') AS time_utc,\n"
    "       i.n, i.mean_kg, i.std_kg, i.baseline_mean_kg, i.baseline_std_kg, i.std_ratio,\n"
    "       i.p_value, i.state,\n"
    "       a.id AS alert_id, a.level AS alert_level, a.kind AS alert_kind,\n"
    "       a.raised AS alert_raised, a.message AS alert_message\n"
    "FROM indicators AS i LEFT JOIN alerts AS a ON a.indicator_id = i.id\n"
    "ORDER BY i.utime, i.id, a.id;\n"
    "\n"
    "CREATE VIEW passage_errors AS\n"
    "WITH pt AS (\n"
    "  SELECT p.*,\n"
    "         (SELECT t.id FROM truth AS t\n"
    "          WHERE t.vehicle_id = p.vehicle_id\n"
    "            AND abs(t.utime - p.utime) = (SELECT min(abs(t2.utime - p.utime)) FROM truth AS t2\n"
    "                                          WHERE t2.vehicle_id = p.vehicle_id)\n"
    "          ORDER BY t.id LIMIT 1) AS truth_id  -- same vehicle_id, nearest in time\n"
    "  FROM passages AS p\n"
    ")\n"
    "SELECT pt.id AS passage_id, pt.vehicle_id, pt.utime, pt.status,\n"
    "       pt.gvw_kg, t.gvw_kg AS true_gvw_kg,\n"
    "       100.0 * (pt.gvw_kg - t.gvw_kg) / t.gvw_kg AS gvw_error_pct,  -- %, NULL when not solved\n"
    "       pt.speed_mps, t.speed_true_mps, pt.n_axles, t.n_axles AS true_n_axles, t.id AS truth_id\n"
    "FROM pt JOIN truth AS t ON t.id = pt.truth_id;\n";

/* Version 2: one row per start of amfid (which program version ran, on
 * which configuration, from when). */
static const char schema_v2[] =
    "CREATE TABLE runs (\n"
    "  id          INTEGER PRIMARY KEY,\n"
    "  started_at  TEXT NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ', 'now')),  -- wall clock, UTC\n"
    "  version     TEXT NOT NULL CHECK (length(version) BETWEEN 1 AND 63),  -- amfid --version\n"
    "  config_path TEXT NOT NULL CHECK (length(CAST(config_path AS BLOB)) BETWEEN 1 AND 4096)  -- file read\n"
    ") STRICT;\n";

/* Version 3 (issue 12): the detector's speed beside the one weighed with
 * (speed_mps, the estimate when solver.speed is estimate). Rows written
 * before it were weighed with the detector's speed: it is copied. */
static const char schema_v3[] =
    "ALTER TABLE passages ADD COLUMN speed_given_mps REAL\n"
    "  CHECK (speed_given_mps BETWEEN 0 AND 150);\n"
    "ALTER TABLE passages ADD COLUMN speed_estimated INTEGER NOT NULL DEFAULT 0\n"
    "  CHECK (speed_estimated IN (0, 1));\n"
    "UPDATE passages SET speed_given_mps = speed_mps;\n";

/* Version 4 (issue 13): vehicles that shared the span are weighed together
 * (amfid's event solve, amfi_solve_multi). n_vehicles is the size of the
 * event a passage was weighed in (1 alone); quality the figure of how well
 * its weight is separated from the others' (amfi_vehicle_result.quality:
 * since issue 13's fourth round 1 + the % change of the weight at λ/10, 1
 * alone; at first the separability figure, now its own field). Rows written
 * before were single-vehicle passages: n_vehicles 1, quality NULL. */
static const char schema_v4[] =
    "ALTER TABLE passages ADD COLUMN n_vehicles INTEGER NOT NULL DEFAULT 1\n"
    "  CHECK (n_vehicles BETWEEN 1 AND 64);\n"
    "ALTER TABLE passages ADD COLUMN quality REAL\n"
    "  CHECK (quality >= 1 AND quality <= 1e9);\n";

/* Version 5 (issue 14): the bridge's environment as amfid received it on
 * the environment channel (environment_t): deck and air temperature at a
 * data time, and when amfid received it (wall clock, µs). */
static const char schema_v5[] =
    "CREATE TABLE environment (\n"
    "  id             INTEGER PRIMARY KEY,\n"
    "  utime          INTEGER NOT NULL  -- data time of the reading, µs\n"
    "                 CHECK (utime BETWEEN 0 AND 253402300799999999),\n"
    "  deck_c         REAL NOT NULL CHECK (deck_c BETWEEN -60 AND 80),  -- deck temperature, °C\n"
    "  air_c          REAL NOT NULL CHECK (air_c BETWEEN -60 AND 80),   -- air temperature, °C\n"
    "  received_utime INTEGER NOT NULL  -- wall clock when amfid received it, µs\n"
    "                 CHECK (received_utime BETWEEN 0 AND 253402300799999999)\n"
    ") STRICT;\n"
    "CREATE INDEX environment_utime ON environment (utime);\n";

/* Version 6 (issue 14): the scale and known-truck indicators in amfid.
 * passages.reference_gvw_kg is a calibration truck's pre-weighed GVW
 * (vehicle_t.reference_gvw_kg), passages.deck_c the deck temperature amfid
 * took for the passage (the environment readings around its time; NULL:
 * none within alerts.scale.max_temp_gap_s, or the scale indicator off);
 * scale_evals holds each scale block and each known-truck run. Rows
 * written before have neither (NULL). */
static const char schema_v6[] =
    "ALTER TABLE passages ADD COLUMN reference_gvw_kg REAL\n"
    "  CHECK (reference_gvw_kg BETWEEN 1000 AND 100000);\n"
    "ALTER TABLE passages ADD COLUMN deck_c REAL\n"
    "  CHECK (deck_c BETWEEN -60 AND 80);\n"
    "CREATE TABLE scale_evals (\n"
    "  id       INTEGER PRIMARY KEY,\n"
    "  utime    INTEGER NOT NULL  -- data time of the block's newest passage / of the run, µs\n"
    "           CHECK (utime BETWEEN 0 AND 253402300799999999),\n"
    "  kind     TEXT NOT NULL CHECK (kind IN ('scale_shift', 'known_truck')),\n"
    "  n        INTEGER NOT NULL CHECK (n >= 0),  -- vehicles in the block / runs so far\n"
    "  value    REAL CHECK (value > 0 AND value <= 100),  -- compensated scale / ratio\n"
    "  raw      REAL CHECK (raw > 0 AND raw <= 100),      -- the same without compensation\n"
    "  deck_c   REAL CHECK (deck_c BETWEEN -60 AND 80),   -- block's mean / run's deck temperature\n"
    "  z        REAL CHECK (z BETWEEN -1e6 AND 1e6),      -- standardized increment\n"
    "  cusum    REAL CHECK (cusum BETWEEN 0 AND 1e6),     -- CUSUM statistic after it\n"
    "  h        REAL CHECK (h BETWEEN 0 AND 1e6),         -- its threshold\n"
    "  state    TEXT NOT NULL CHECK (state IN ('baseline', 'normal', 'watch', 'alert'))\n"
    ") STRICT;\n"
    "CREATE INDEX scale_evals_kind_utime ON scale_evals (kind, utime);\n";
/* Version 7 (issue 14, item 4): the bridge's first natural frequency from
 * the passage's free vibration after the last axle left (amfid's
 * daemon.natural_frequency): f1_hz as estimated, f1_comp_hz brought to the
 * calibration temperature by the baseline's fit (NULL before it exists),
 * its damping ratio and the fit's R². NULL when not estimated or refused
 * (amfid counts the reasons), and in rows written before. */
static const char schema_v7[] =
    "ALTER TABLE passages ADD COLUMN f1_hz REAL\n"
    "  CHECK (f1_hz > 0 AND f1_hz <= 1000);\n"
    "ALTER TABLE passages ADD COLUMN f1_comp_hz REAL\n"
    "  CHECK (f1_comp_hz > 0 AND f1_comp_hz <= 1000);\n"
    "ALTER TABLE passages ADD COLUMN f1_zeta REAL\n"
    "  CHECK (f1_zeta >= 0 AND f1_zeta < 1);\n"
    "ALTER TABLE passages ADD COLUMN f1_r2 REAL\n"
    "  CHECK (f1_r2 >= 0 AND f1_r2 <= 1);\n";

/* Version 8 (issue 14): the weight the STD and mean rules were fed
 * (daemon.indicators.temperature: compensated): the inferred GVW brought to
 * the calibration temperature by the scale indicator's temperature model;
 * the GVW itself when the passage had no deck temperature or the rules take
 * raw weights. NULL for passages that did not feed the rules and in rows
 * written before (whose GVW is what the rules were fed). */
static const char schema_v8[] =
    "ALTER TABLE passages ADD COLUMN gvw_comp_kg REAL\n"
    "  CHECK (gvw_comp_kg > 0 AND gvw_comp_kg <= 1000000);\n";

/* Version 9: the refused bus messages, summarised once per
 * daemon.intake.summary_period_s (wall clock) by input channel and reason,
 * with the first one's log line: a flood of refused messages costs one row
 * per channel and reason a period, not one fsync'd row each. */
static const char schema_v9[] =
    "CREATE TABLE refusals (\n"
    "  id           INTEGER PRIMARY KEY,\n"
    "  period_start INTEGER NOT NULL  -- wall clock, µs: the period's start\n"
    "               CHECK (period_start BETWEEN 0 AND 253402300799999999),\n"
    "  period_end   INTEGER NOT NULL  -- wall clock, µs: when it was summarised\n"
    "               CHECK (period_end BETWEEN period_start AND 253402300799999999),\n"
    "  channel      TEXT NOT NULL CHECK (length(channel) BETWEEN 1 AND 63),  -- the bus channel\n"
    "  input        TEXT NOT NULL CHECK (input IN ('accel', 'vehicle', 'truth', 'environment')),\n"
    "  reason       TEXT NOT NULL CHECK (length(reason) BETWEEN 1 AND 63),\n"
    "  count        INTEGER NOT NULL CHECK (count >= 1),  -- refused in the period for this reason\n"
    "  example      TEXT NOT NULL CHECK (length(example) <= 512)  -- the first one's log line\n"
    ") STRICT;\n"
    "CREATE INDEX refusals_period ON refusals (period_start);\n";

/* Version 10: the vehicle class and axle groups amfid finds from the axle
 * count and spacings (classify/, the site file's classes:), and whether
 * the GVW or a group is above its legal limit (NULL when not solved). NULL
 * in rows written before. */
static const char schema_v10[] =
    "ALTER TABLE passages ADD COLUMN class TEXT\n"
    "  CHECK (length(class) BETWEEN 1 AND 15);\n"
    "ALTER TABLE passages ADD COLUMN axle_groups TEXT\n"
    "  CHECK (length(axle_groups) BETWEEN 1 AND 31);\n"
    "ALTER TABLE passages ADD COLUMN overload INTEGER\n"
    "  CHECK (overload IN (0, 1));\n";

/* Version 11: the raw samples of each passage's window (amfid's
 * daemon.store.raw): one raw_windows row per window weighed (one vehicle,
 * or an event of several weighed together) with the samples of every
 * sensor exactly as the solver had them (float64, compressed: encoding),
 * the time base, the sensors, the detector records and the solver's
 * settings it was weighed with; one passage_raw row per passage linking it
 * to its window. Retention deletes raw_windows rows (their links go with
 * them); the passages stay. */
static const char schema_v11[] =
    "CREATE TABLE raw_windows (\n"
    "  id         INTEGER PRIMARY KEY,\n"
    "  utime      INTEGER NOT NULL  -- data time of the first vehicle's entry (t = 0), µs\n"
    "             CHECK (utime BETWEEN 0 AND 253402300799999999),\n"
    "  rate_hz    REAL NOT NULL CHECK (rate_hz > 0 AND rate_hz <= 100000),  -- sample rate, Hz\n"
    "  t_first_s  REAL NOT NULL CHECK (t_first_s BETWEEN -3600 AND 3600),  -- first sample's time, s\n"
    "  n_samples  INTEGER NOT NULL CHECK (n_samples BETWEEN 1 AND 2147483647),  -- per sensor\n"
    "  sensors    TEXT NOT NULL CHECK (length(sensors) BETWEEN 3 AND 1024),  -- ID@AT_M,... in the samples' order\n"
    "  vehicles   TEXT NOT NULL CHECK (length(vehicles) BETWEEN 7 AND 32768),  -- the detector records weighed\n"
    "  solve      TEXT NOT NULL CHECK (length(solve) BETWEEN 1 AND 1024),  -- the solver's settings\n"
    "  encoding   TEXT NOT NULL  -- how samples is encoded (float64 exact, or rounded to float32)\n"
    "             CHECK (encoding IN ('f64-xor-shuffle-zlib', 'f32-xor-shuffle-zlib')),\n"
    "  bytes      INTEGER NOT NULL CHECK (bytes >= 1),  -- length(samples)\n"
    "  samples    BLOB NOT NULL CHECK (length(samples) = bytes)  -- every sensor's samples, compressed\n"
    ") STRICT;\n"
    "CREATE INDEX raw_windows_utime ON raw_windows (utime, bytes);\n"
    "CREATE TABLE passage_raw (\n"
    "  passage_id INTEGER PRIMARY KEY REFERENCES passages (id) ON DELETE CASCADE,\n"
    "  window_id  INTEGER NOT NULL REFERENCES raw_windows (id) ON DELETE CASCADE,\n"
    "  vehicle    INTEGER NOT NULL CHECK (vehicle BETWEEN 0 AND 63)  -- its place in the window's vehicles\n"
    ") STRICT;\n"
    "CREATE INDEX passage_raw_window ON passage_raw (window_id);\n";
/* Version 12: the model fit of each passage weighed alone (amfid's
 * modelfit.c, the model_mismatch alert): the residual of the site's model
 * over the free vibration after the last axle, relative to the signal
 * there. NULL in rows written before and where not fitted. */
static const char schema_v12[] =
    "ALTER TABLE passages ADD COLUMN fit_ratio REAL\n"
    "  CHECK (fit_ratio > 0 AND fit_ratio <= 1000);\n";

/* Version 13: why the classification refused a passage's loads (classify/
 * loads_why: a single axle or a group below zero, or above ten times any
 * legal load of its axle count), written by amfid's classes module; such a
 * passage's overload stays NULL. NULL where the loads were judged, where
 * there were none, and in rows written before (amfi-report recomputes the
 * refusal for those). */
static const char schema_v13[] =
    "ALTER TABLE passages ADD COLUMN loads_refused TEXT\n"
    "  CHECK (length(loads_refused) BETWEEN 1 AND 111);\n";

const st_migration st_migrations[] = {
    {1, "passages, axles, truth, truth_axles, indicators, alerts, baseline, "
        "meta; views daily_trend, window_trend, passage_errors", schema_v1},
    {2, "runs: program version and configuration of each start of amfid", schema_v2},
    {3, "passages: speed_given_mps (the detector's) and speed_estimated", schema_v3},
    {4, "passages: n_vehicles (vehicles weighed together) and quality", schema_v4},
    {5, "environment: deck and air temperature received on the bus", schema_v5},
    {6, "passages: reference_gvw_kg and deck_c; scale_evals (scale and known truck)",
     schema_v6},
    {7, "passages: f1_hz, f1_comp_hz, f1_zeta, f1_r2 (natural frequency)", schema_v7},
    {8, "passages: gvw_comp_kg (the weight the STD and mean rules were fed)", schema_v8},
    {9, "refusals: refused bus messages summarised per period, channel and reason", schema_v9},
    {10, "passages: class, axle_groups and overload (classify/)", schema_v10},
    {11, "raw_windows, passage_raw: each passage's raw samples (retention by age and size)",
     schema_v11},
    {12, "passages: fit_ratio (the model's residual over the free vibration)", schema_v12},
    {13, "passages: loads_refused (why the classification refused the loads)", schema_v13},
};
const int st_n_migrations = (int)(sizeof st_migrations / sizeof st_migrations[0]);
_Static_assert(sizeof st_migrations / sizeof st_migrations[0]
                   == AMFI_STORE_SCHEMA_VERSION,
               "one migration per schema version");
