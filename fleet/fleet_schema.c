/* SPDX-License-Identifier: GPL-3.0-or-later */
/* The central PostgreSQL schema, version by version (docs/fleet.md shows it).
 * Every site table gains site_id; (site_id, id) is the key, so a batch shipped
 * twice fails instead of doubling. fleet_sync_state holds each site's
 * per-table high-water mark and the hash of the last shipped row. */
#include "fleet_schema.h"

#include <stddef.h>

static const char fleet_v1[] =
    "CREATE TABLE passages (\n"
    "  site_id text NOT NULL, id bigint NOT NULL, vehicle_id bigint NOT NULL,\n"
    "  utime bigint NOT NULL,  -- µs since 1970 UTC\n"
    "  lane integer NOT NULL, speed_mps double precision, n_axles integer NOT NULL,\n"
    "  gvw_kg double precision, status text NOT NULL, reason text NOT NULL,\n"
    "  lambda double precision, residual_rms double precision, formulation text,\n"
    "  solve_ms double precision, stored_at text NOT NULL,\n"
    "  PRIMARY KEY (site_id, id));\n"
    "CREATE INDEX passages_site_utime ON passages (site_id, utime);\n"
    "CREATE TABLE axles (\n"
    "  site_id text NOT NULL, passage_id bigint NOT NULL, idx integer NOT NULL,\n"
    "  spacing_m double precision, load_kg double precision,\n"
    "  PRIMARY KEY (site_id, passage_id, idx));\n"
    "CREATE TABLE indicators (\n"
    "  site_id text NOT NULL, id bigint NOT NULL, utime bigint NOT NULL, n integer NOT NULL,\n"
    "  mean_kg double precision, std_kg double precision, baseline_mean_kg double precision,\n"
    "  baseline_std_kg double precision, std_ratio double precision, p_value double precision,\n"
    "  state text NOT NULL, PRIMARY KEY (site_id, id));\n"
    "CREATE INDEX indicators_site_utime ON indicators (site_id, utime);\n"
    "CREATE TABLE alerts (\n"
    "  site_id text NOT NULL, id bigint NOT NULL, utime bigint NOT NULL, level text NOT NULL,\n"
    "  kind text NOT NULL, message text NOT NULL, indicator_id bigint, raised integer NOT NULL,\n"
    "  PRIMARY KEY (site_id, id));\n"
    "CREATE TABLE baseline (\n"
    "  site_id text NOT NULL, id bigint NOT NULL, utime_set bigint NOT NULL, n integer NOT NULL,\n"
    "  mean_kg double precision NOT NULL, std_kg double precision NOT NULL, source text NOT NULL,\n"
    "  note text NOT NULL, set_at text NOT NULL, PRIMARY KEY (site_id, id));\n"
    "CREATE TABLE runs (\n"
    "  site_id text NOT NULL, id bigint NOT NULL, started_at text NOT NULL, version text NOT NULL,\n"
    "  config_path text NOT NULL, PRIMARY KEY (site_id, id));\n"
    "CREATE TABLE fleet_sync_state (\n"
    "  site_id text NOT NULL, tbl text NOT NULL,\n"
    "  hwm bigint NOT NULL,         -- newest local id shipped\n"
    "  last_hash text NOT NULL,     -- FNV-1a of that row's text, hex\n"
    "  synced_at timestamptz NOT NULL DEFAULT now(),\n"
    "  PRIMARY KEY (site_id, tbl));\n"
    "CREATE VIEW fleet_latest_state AS\n"
    "  SELECT DISTINCT ON (site_id) site_id, id AS indicator_id, utime, n, mean_kg, std_kg,\n"
    "         std_ratio, p_value, state\n"
    "  FROM indicators ORDER BY site_id, utime DESC, id DESC;\n"
    "CREATE VIEW fleet_open_alerts AS\n"
    "  SELECT * FROM (SELECT DISTINCT ON (site_id, kind) site_id, id AS alert_id, utime, level, kind,\n"
    "                        message, indicator_id, raised\n"
    "                 FROM alerts ORDER BY site_id, kind, utime DESC, id DESC) AS last\n"
    "  WHERE raised = 1;\n"
    "CREATE VIEW fleet_daily_trend AS\n"
    "  SELECT site_id, (to_timestamp(utime / 1e6) AT TIME ZONE 'UTC')::date AS day,\n"
    "         count(*) FILTER (WHERE status = 'ok') AS n_ok,\n"
    "         avg(gvw_kg) FILTER (WHERE status = 'ok') AS mean_kg,\n"
    "         stddev_samp(gvw_kg) FILTER (WHERE status = 'ok') AS std_kg,\n"
    "         count(*) FILTER (WHERE status <> 'ok') AS n_not_ok\n"
    "  FROM passages GROUP BY 1, 2;\n"
    "CREATE VIEW fleet_passages_daily AS\n"
    "  SELECT site_id, (to_timestamp(utime / 1e6) AT TIME ZONE 'UTC')::date AS day, status,\n"
    "         count(*) AS n\n"
    "  FROM passages GROUP BY 1, 2, 3;\n";

/* Version 2: the site store's window_trend, per site (each indicator with
 * the alerts it raised or cleared). */
static const char fleet_v2[] =
    "CREATE VIEW fleet_window_trend AS\n"
    "  SELECT i.site_id, i.id AS indicator_id, i.utime,\n"
    "         to_timestamp(i.utime / 1e6) AS time_utc, i.n, i.mean_kg, i.std_kg,\n"
    "         i.baseline_mean_kg, i.baseline_std_kg, i.std_ratio, i.p_value, i.state,\n"
    "         a.id AS alert_id, a.level AS alert_level, a.kind AS alert_kind,\n"
    "         a.raised AS alert_raised, a.message AS alert_message\n"
    "  FROM indicators AS i\n"
    "  LEFT JOIN alerts AS a ON a.site_id = i.site_id AND a.indicator_id = i.id;\n";

/* Version 3: the passage's detector speed and whether the speed used was
 * estimated (site store version 3, issue 12). Rows shipped before: the
 * detector speed unknown (NULL), not estimated (0, as the site store says
 * of them). A constant default adds the column without rewriting the
 * table. */
static const char fleet_v3[] =
    "ALTER TABLE passages ADD COLUMN speed_given_mps double precision,\n"
    "  ADD COLUMN speed_estimated integer NOT NULL DEFAULT 0;\n";

/* Version 4: the number of vehicles of the event a passage was weighed in
 * and its quality figure (site store version 4, issue 13). Rows shipped
 * before: weighed alone (1), no quality (NULL), as the site store says of
 * them. */
static const char fleet_v4[] =
    "ALTER TABLE passages ADD COLUMN n_vehicles integer NOT NULL DEFAULT 1,\n"
    "  ADD COLUMN quality double precision;\n";

const struct fleet_migration fleet_migrations[] = {
    {1, "site tables with site_id, fleet_sync_state, fleet views", fleet_v1},
    {2, "fleet_window_trend: indicators with their alerts, per site", fleet_v2},
    {3, "passages: speed_given_mps and speed_estimated", fleet_v3},
    {4, "passages: n_vehicles and quality", fleet_v4},
};
const int fleet_n_migrations = (int)(sizeof fleet_migrations / sizeof fleet_migrations[0]);

const struct fleet_table fleet_tables[] = {
    {"passages",
     "id, vehicle_id, utime, lane, speed_mps, n_axles, gvw_kg, status, reason, lambda, "
     "residual_rms, formulation, solve_ms, stored_at, speed_given_mps, speed_estimated, "
     "n_vehicles, quality", 14,
     "axles", "passage_id, idx, spacing_m, load_kg", "passage_id"},
    {"indicators",
     "id, utime, n, mean_kg, std_kg, baseline_mean_kg, baseline_std_kg, std_ratio, p_value, state", 10,
     NULL, NULL, NULL},
    {"alerts", "id, utime, level, kind, message, indicator_id, raised", 7, NULL, NULL, NULL},
    {"baseline", "id, utime_set, n, mean_kg, std_kg, source, note, set_at", 8, NULL, NULL, NULL},
    {"runs", "id, started_at, version, config_path", 4, NULL, NULL, NULL},
};
const int fleet_n_tables = (int)(sizeof fleet_tables / sizeof fleet_tables[0]);
