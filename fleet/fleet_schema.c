/* SPDX-License-Identifier: GPL-3.0-or-later */
/* The central PostgreSQL schema, version by version (docs/fleet.md shows it).
 * Every site table gains site_id; (site_id, id) is the key, so a batch shipped
 * twice fails instead of doubling. fleet_sync_state holds each site's
 * per-table high-water mark and the hash of the last shipped row. */
#include "fleet_schema.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "store.h"

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

/* Version 5 (issue 14; site store versions 5-8): the passages' known-truck
 * reference weight, deck temperature, natural frequency and the weight the
 * STD and mean rules were fed (temperature-compensated); the site's
 * temperature readings (environment) and its scale indicator's blocks and
 * known-truck runs (scale_evals); the newest of those per site and kind.
 * Rows shipped before keep NULL in the new passage columns (the site store
 * says NULL of rows written before its migrations; a store already at
 * version 8 before this step had its values, which amfi-sync cannot update
 * centrally: docs/fleet.md). The roles of docs/fleet.md, where they exist,
 * get the same rights on the new tables as on the others (their default
 * privileges only cover tables created by the role that set them). */
static const char fleet_v5[] =
    "ALTER TABLE passages ADD COLUMN reference_gvw_kg double precision,\n"
    "  ADD COLUMN deck_c double precision, ADD COLUMN f1_hz double precision,\n"
    "  ADD COLUMN f1_comp_hz double precision, ADD COLUMN f1_zeta double precision,\n"
    "  ADD COLUMN f1_r2 double precision, ADD COLUMN gvw_comp_kg double precision;\n"
    "CREATE TABLE environment (\n"
    "  site_id text NOT NULL, id bigint NOT NULL, utime bigint NOT NULL,\n"
    "  deck_c double precision NOT NULL, air_c double precision NOT NULL,\n"
    "  received_utime bigint NOT NULL, PRIMARY KEY (site_id, id));\n"
    "CREATE INDEX environment_site_utime ON environment (site_id, utime);\n"
    "CREATE TABLE scale_evals (\n"
    "  site_id text NOT NULL, id bigint NOT NULL, utime bigint NOT NULL, kind text NOT NULL,\n"
    "  n integer NOT NULL, value double precision, raw double precision,\n"
    "  deck_c double precision, z double precision, cusum double precision,\n"
    "  h double precision, state text NOT NULL, PRIMARY KEY (site_id, id));\n"
    "CREATE INDEX scale_evals_site_kind_utime ON scale_evals (site_id, kind, utime);\n"
    "CREATE VIEW fleet_latest_scale AS\n"
    "  SELECT DISTINCT ON (site_id, kind) site_id, kind, id AS scale_eval_id, utime, n, value,\n"
    "         raw, deck_c, z, cusum, h, state\n"
    "  FROM scale_evals ORDER BY site_id, kind, utime DESC, id DESC;\n"
    "DO $$ BEGIN\n"
    "  IF EXISTS (SELECT 1 FROM pg_roles WHERE rolname = 'amfi_sync') THEN\n"
    "    GRANT SELECT, INSERT ON environment, scale_evals, fleet_latest_scale TO amfi_sync;\n"
    "  END IF;\n"
    "  IF EXISTS (SELECT 1 FROM pg_roles WHERE rolname = 'amfi_reader') THEN\n"
    "    GRANT SELECT ON environment, scale_evals, fleet_latest_scale TO amfi_reader;\n"
    "  END IF;\n"
    "END $$;\n";

/* Version 6: each site writes and reads only its own rows. The group roles
 * amfi_site (every site's login role is a member) and amfi_reader (analysts,
 * amfi-report --pg) are created when missing; fleet_site_roles maps each
 * site's login role to its site (one role per site, created by the owner's
 * 'amfi-sync --init-site-role SITE'); row-level security on every table a
 * site writes or reads binds a site role to the rows of its site, USING and
 * WITH CHECK, its marks in fleet_sync_state included. The owner is not bound
 * (ENABLE, not FORCE: it owns the tables and could lift the policies anyway;
 * it migrates and repairs). fleet_migrations is written by the owner only:
 * every other role's write rights on it are revoked. The shared writer of
 * the versions before, amfi_sync, loses every right (one login for every
 * site is what let a site forge another's rows). The views are read by the
 * owner and amfi_reader only (a view runs with its owner's rights, so a
 * site role reading one would see every site). */
static const char fleet_v6[] =
    "DO $$ BEGIN\n"
    "  IF NOT EXISTS (SELECT 1 FROM pg_roles WHERE rolname = 'amfi_site') THEN\n"
    "    CREATE ROLE amfi_site NOLOGIN;\n"
    "  END IF;\n"
    "  IF NOT EXISTS (SELECT 1 FROM pg_roles WHERE rolname = 'amfi_reader') THEN\n"
    "    CREATE ROLE amfi_reader NOLOGIN;\n"
    "  END IF;\n"
    "END $$;\n"
    "CREATE TABLE fleet_site_roles (\n"
    "  role_name text PRIMARY KEY,  -- a login role, member of amfi_site\n"
    "  site_id text NOT NULL UNIQUE,\n"
    "  created_at timestamptz NOT NULL DEFAULT now());\n"
    "REVOKE ALL ON fleet_migrations, fleet_site_roles, fleet_sync_state, passages, axles,\n"
    "  indicators, alerts, baseline, runs, environment, scale_evals, fleet_latest_state,\n"
    "  fleet_open_alerts, fleet_daily_trend, fleet_passages_daily, fleet_window_trend,\n"
    "  fleet_latest_scale FROM PUBLIC;\n"
    "DO $$ DECLARE g text; BEGIN\n"
    "  FOR g IN SELECT DISTINCT a.grantee::regrole::text\n"
    "           FROM pg_class AS c, aclexplode(c.relacl) AS a\n"
    "           WHERE c.oid = 'fleet_migrations'::regclass AND a.grantee <> 0\n"
    "             AND a.grantee <> c.relowner AND a.privilege_type <> 'SELECT' LOOP\n"
    "    EXECUTE format('REVOKE INSERT, UPDATE, DELETE, TRUNCATE, REFERENCES, TRIGGER '\n"
    "                   'ON fleet_migrations FROM %s', g);\n"
    "  END LOOP;\n"
    "  IF EXISTS (SELECT 1 FROM pg_roles WHERE rolname = 'amfi_sync') THEN\n"
    "    EXECUTE format('REVOKE ALL ON ALL TABLES IN SCHEMA %I FROM amfi_sync', current_schema());\n"
    "    EXECUTE format('ALTER DEFAULT PRIVILEGES IN SCHEMA %I REVOKE ALL ON TABLES FROM amfi_sync',\n"
    "                   current_schema());\n"
    "  END IF;\n"
    "END $$;\n"
    "GRANT SELECT ON fleet_migrations, fleet_site_roles TO amfi_site;\n"
    "GRANT SELECT, INSERT ON passages, axles, indicators, alerts, baseline, runs, environment,\n"
    "  scale_evals TO amfi_site;\n"
    "GRANT SELECT, INSERT, UPDATE ON fleet_sync_state TO amfi_site;\n"
    "GRANT SELECT ON fleet_migrations, fleet_site_roles, fleet_sync_state, passages, axles,\n"
    "  indicators, alerts, baseline, runs, environment, scale_evals, fleet_latest_state,\n"
    "  fleet_open_alerts, fleet_daily_trend, fleet_passages_daily, fleet_window_trend,\n"
    "  fleet_latest_scale TO amfi_reader;\n"
    "ALTER TABLE fleet_site_roles ENABLE ROW LEVEL SECURITY;\n"
    "CREATE POLICY fleet_own_role ON fleet_site_roles FOR SELECT TO amfi_site\n"
    "  USING (role_name = current_user);\n"
    "CREATE POLICY fleet_reader ON fleet_site_roles FOR SELECT TO amfi_reader USING (true);\n"
    "DO $$ DECLARE t text; BEGIN\n"
    "  FOREACH t IN ARRAY ARRAY['passages', 'axles', 'indicators', 'alerts', 'baseline', 'runs',\n"
    "                           'environment', 'scale_evals', 'fleet_sync_state'] LOOP\n"
    "    EXECUTE format('ALTER TABLE %I ENABLE ROW LEVEL SECURITY', t);\n"
    "    EXECUTE format('CREATE POLICY fleet_site ON %I TO amfi_site '\n"
    "      'USING (site_id = (SELECT r.site_id FROM fleet_site_roles AS r '\n"
    "      'WHERE r.role_name = current_user)) '\n"
    "      'WITH CHECK (site_id = (SELECT r.site_id FROM fleet_site_roles AS r '\n"
    "      'WHERE r.role_name = current_user))', t);\n"
    "    EXECUTE format('CREATE POLICY fleet_reader ON %I FOR SELECT TO amfi_reader USING (true)', t);\n"
    "  END LOOP;\n"
    "END $$;\n";

/* Version 7 (site store version 10): the passages' vehicle class, axle
 * groups and overload, as amfid's classes module stores them. Rows shipped
 * before keep NULL (as the site store's rows written before its migration). */
static const char fleet_v7[] =
    "ALTER TABLE passages ADD COLUMN class text, ADD COLUMN axle_groups text,\n"
    "  ADD COLUMN overload integer;\n";

/* Version 8: the sites themselves and times people read. fleet_sites holds
 * each site's name, position and bridge type (the store's meta, written by
 * amfid from site.* of amfid.yaml, shipped by amfi-sync at every pass) and
 * which store ships it: the started_at of the store's first run (runs id 1,
 * written once at the store's first start), so that a second store claiming
 * the same site id is told so (amfi-sync, docs/fleet.md "Two stores, one
 * site id") instead of being taken for a restored backup. Sites shipped
 * before get their row from their central runs row 1 (claimed_at: that
 * run's start). The views give times as timestamptz (column `time`), exact
 * to the µs, instead of µs integers; fleet_summary is the fleet summary of
 * amfi-report --pg, one row per site. Then roles.sql (fleet_roles_sql.h:
 * the one source of the roles and row-level security, run by amfi-sync
 * after the last migration from this version on) gives fleet_sites and the
 * views their rights. */
static const char fleet_v8[] =
    "CREATE TABLE fleet_sites (\n"
    "  site_id text PRIMARY KEY,\n"
    "  store_started_at text,  -- the shipping store's first run (runs id 1): its identity\n"
    "  name text, latitude double precision CHECK (latitude BETWEEN -90 AND 90),\n"
    "  longitude double precision CHECK (longitude BETWEEN -180 AND 180),\n"
    "  bridge_type text,\n"
    "  claimed_at timestamptz NOT NULL DEFAULT now(),  -- first shipped by that store\n"
    "  updated_at timestamptz NOT NULL DEFAULT now(),\n"
    "  CHECK ((latitude IS NULL) = (longitude IS NULL)));\n"
    "INSERT INTO fleet_sites (site_id, store_started_at, claimed_at)\n"
    "  SELECT site_id, started_at,\n"
    "         CASE WHEN started_at ~ '^[0-9]{4}-[0-9]{2}-[0-9]{2}T[0-9:.]+Z$'\n"
    "              THEN started_at::timestamptz ELSE now() END\n"
    "  FROM runs WHERE id = 1;\n"
    "DROP VIEW fleet_latest_state, fleet_open_alerts, fleet_window_trend, fleet_latest_scale;\n"
    "CREATE VIEW fleet_latest_state AS\n"
    "  SELECT DISTINCT ON (site_id) site_id, id AS indicator_id,\n"
    "         timestamptz 'epoch' + utime * interval '1 microsecond' AS time, n, mean_kg, std_kg,\n"
    "         std_ratio, p_value, state\n"
    "  FROM indicators ORDER BY site_id, utime DESC, id DESC;\n"
    "CREATE VIEW fleet_open_alerts AS\n"
    "  SELECT * FROM (SELECT DISTINCT ON (site_id, kind) site_id, id AS alert_id,\n"
    "                        timestamptz 'epoch' + utime * interval '1 microsecond' AS time,\n"
    "                        level, kind, message, indicator_id, raised\n"
    "                 FROM alerts ORDER BY site_id, kind, utime DESC, id DESC) AS last\n"
    "  WHERE raised = 1;\n"
    "CREATE VIEW fleet_window_trend AS\n"
    "  SELECT i.site_id, i.id AS indicator_id,\n"
    "         timestamptz 'epoch' + i.utime * interval '1 microsecond' AS time, i.n, i.mean_kg,\n"
    "         i.std_kg, i.baseline_mean_kg, i.baseline_std_kg, i.std_ratio, i.p_value, i.state,\n"
    "         a.id AS alert_id, a.level AS alert_level, a.kind AS alert_kind,\n"
    "         a.raised AS alert_raised, a.message AS alert_message\n"
    "  FROM indicators AS i\n"
    "  LEFT JOIN alerts AS a ON a.site_id = i.site_id AND a.indicator_id = i.id;\n"
    "CREATE VIEW fleet_latest_scale AS\n"
    "  SELECT DISTINCT ON (site_id, kind) site_id, kind, id AS scale_eval_id,\n"
    "         timestamptz 'epoch' + utime * interval '1 microsecond' AS time, n, value, raw,\n"
    "         deck_c, z, cusum, h, state\n"
    "  FROM scale_evals ORDER BY site_id, kind, utime DESC, id DESC;\n"
    "CREATE VIEW fleet_summary AS\n"
    "  SELECT s.site_id, f.name, f.latitude, f.longitude, f.bridge_type, s.hwm AS passages,\n"
    "         (SELECT timestamptz 'epoch' + max(p.utime) * interval '1 microsecond'\n"
    "          FROM passages AS p WHERE p.site_id = s.site_id) AS last_passage,\n"
    "         coalesce(l.state, '-') AS state, l.std_ratio,\n"
    "         (SELECT count(*) FROM fleet_open_alerts AS a WHERE a.site_id = s.site_id) AS open_alerts,\n"
    "         (SELECT max(g.synced_at) FROM fleet_sync_state AS g WHERE g.site_id = s.site_id)\n"
    "           AS last_shipped\n"
    "  FROM fleet_sync_state AS s\n"
    "  LEFT JOIN fleet_sites AS f ON f.site_id = s.site_id\n"
    "  LEFT JOIN fleet_latest_state AS l ON l.site_id = s.site_id\n"
    "  WHERE s.tbl = 'passages';\n";

/* Version 9 (site store version 12): the passages' model fit, as amfid's
 * modelfit module stores it. Rows shipped before keep NULL. */
static const char fleet_v9[] = "ALTER TABLE passages ADD COLUMN fit_ratio double precision;\n";

/* Version 10 (site store version 13): why amfid's classification refused a
 * passage's loads (its overload is then NULL). Rows shipped before keep
 * NULL. */
static const char fleet_v10[] = "ALTER TABLE passages ADD COLUMN loads_refused text;\n";

/* roles.sql (the roles and row-level security as they stand now), compiled
 * in by fleet/CMakeLists.txt */
#include "fleet_roles_sql.h"

/* A later version that adds a site table or a view adds it to roles.sql
 * (its row-level security with the two policies fleet_site and
 * fleet_reader, amfi_site's and amfi_reader's rights, the view revoked from
 * PUBLIC and granted to amfi_reader only); amfi-sync runs roles.sql after
 * the last migration it applies (FLEET_ROLES_SQL_FROM;
 * tests/fleet/fleet_security.sh fails on a table with a site_id and no
 * policy). */
const struct fleet_migration fleet_migrations[] = {
    {1, "site tables with site_id, fleet_sync_state, fleet views", fleet_v1},
    {2, "fleet_window_trend: indicators with their alerts, per site", fleet_v2},
    {3, "passages: speed_given_mps and speed_estimated", fleet_v3},
    {4, "passages: n_vehicles and quality", fleet_v4},
    {5, "passages: reference_gvw_kg, deck_c, f1_hz, f1_comp_hz, f1_zeta, f1_r2, gvw_comp_kg; "
        "environment, scale_evals, fleet_latest_scale", fleet_v5},
    {6, "one role per site: fleet_site_roles, row-level security on every site table, "
        "fleet_migrations written by the owner only", fleet_v6},
    {7, "passages: class, axle_groups and overload", fleet_v7},
    {8, "fleet_sites: name, position, bridge type and store of each site; fleet_summary; "
        "times in the views as timestamptz", fleet_v8},
    {9, "passages: fit_ratio (the model fit)", fleet_v9},
    {10, "passages: loads_refused (why the classification refused the loads)", fleet_v10},
};
const char *const fleet_roles_sql = fleet_roles_sql_text;
const int fleet_n_migrations = (int)(sizeof fleet_migrations / sizeof fleet_migrations[0]);

const struct fleet_table fleet_tables[] = {
    {"passages", "axles", "passage_id"},
    {"indicators", NULL, NULL},
    {"alerts", NULL, NULL},
    {"baseline", NULL, NULL},
    {"runs", NULL, NULL},
    /* central version 5 */
    {"environment", NULL, NULL},
    {"scale_evals", NULL, NULL},
};
const int fleet_n_tables = (int)(sizeof fleet_tables / sizeof fleet_tables[0]);

int fleet_columns(const char *table, const amfi_store_coldef **defs, const char **names, int max)
{
    const amfi_store_tabledef *t = amfi_store_tabledef_find(table);
    int n = 0;
    for (int k = 0; t && k < t->ncols && n < max; k++) {
        if (!t->cols[k].shipped)
            continue;
        if (defs) defs[n] = &t->cols[k];
        if (names) names[n] = t->cols[k].name;
        n++;
    }
    return n;
}

void fleet_cols_text(const char *table, char *buf, size_t len)
{
    const char *names[64];
    int n = fleet_columns(table, NULL, names, 64);
    size_t k = 0;
    buf[0] = '\0';
    for (int j = 0; j < n && k < len; j++)
        k += (size_t)snprintf(buf + k, len - k, "%s%s", j ? ", " : "", names[j]);
}

int fleet_hash_cols(const char *table)
{
    const amfi_store_coldef *defs[64];
    int n = fleet_columns(table, defs, NULL, 64), first = 0, h = 0;
    for (int j = 0; j < n; j++)
        if (!first || defs[j]->shipped < first) first = defs[j]->shipped;
    for (int j = 0; j < n && defs[j]->shipped == first; j++) h++;
    return h;
}

int fleet_site_text_ok(const char *s)
{
    const unsigned char *p = (const unsigned char *)s;
    while (*p) {
        int n = *p < 0x80 ? 1 : (*p & 0xe0) == 0xc0 && *p >= 0xc2 ? 2 : (*p & 0xf0) == 0xe0 ? 3
              : (*p & 0xf8) == 0xf0 && *p <= 0xf4 ? 4 : 0;
        if (!n || (n == 1 && (*p < 0x20 || *p == 0x7f))) return 0;
        for (int k = 1; k < n; k++)
            if ((p[k] & 0xc0) != 0x80) return 0;
        p += n;
    }
    return 1;
}

int fleet_site_coord_ok(const char *s, double lim)
{
    char *end;
    errno = 0;
    double x = strtod(s, &end);
    return end != s && !*end && errno == 0 && x >= -lim && x <= lim;
}
