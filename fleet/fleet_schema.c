/* SPDX-License-Identifier: GPL-3.0-or-later */
/* The central PostgreSQL schema, version by version (docs/fleet.md shows it).
 * Every site table gains site_id; (site_id, id) is the key, so a batch shipped
 * twice fails instead of doubling. fleet_sync_state holds each site's
 * per-table high-water mark and the hash of the last shipped row. */
#include "fleet_schema.h"

#include <math.h>
#include <stdio.h>
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

/* A later version that adds a site table enables row-level security on it
 * with the two policies of version 6 (fleet_site, fleet_reader), grants
 * amfi_site SELECT, INSERT and amfi_reader SELECT on it, and revokes a new
 * view from PUBLIC and grants it to amfi_reader only (tests/fleet/fleet_security.sh
 * fails on a table with a site_id and no policy). */
const struct fleet_migration fleet_migrations[] = {
    {1, "site tables with site_id, fleet_sync_state, fleet views", fleet_v1},
    {2, "fleet_window_trend: indicators with their alerts, per site", fleet_v2},
    {3, "passages: speed_given_mps and speed_estimated", fleet_v3},
    {4, "passages: n_vehicles and quality", fleet_v4},
    {5, "passages: reference_gvw_kg, deck_c, f1_hz, f1_comp_hz, f1_zeta, f1_r2, gvw_comp_kg; "
        "environment, scale_evals, fleet_latest_scale", fleet_v5},
    {6, "one role per site: fleet_site_roles, row-level security on every site table, "
        "fleet_migrations written by the owner only", fleet_v6},
};
const int fleet_n_migrations = (int)(sizeof fleet_migrations / sizeof fleet_migrations[0]);

/* The site store's rules per column (store/store_schema.c, docs/schema.md). */
#define UT_MAX AMFI_STORE_MAX_UTIME
#define KG AMFI_STORE_MAX_KG
#define I_(n, lo, hi) {n, FLEET_INT, 0, 0, 0, 0, lo, hi, NULL, 0, 0}
#define IN(n, lo, hi) {n, FLEET_INT, 1, 0, 0, 0, lo, hi, NULL, 0, 0}
#define R_(n, open, lo, hi) {n, FLEET_REAL, 0, open, lo, hi, 0, 0, NULL, 0, 0}
#define RN(n, open, lo, hi) {n, FLEET_REAL, 1, open, lo, hi, 0, 0, NULL, 0, 0}
#define T_(n, values, lo, hi) {n, FLEET_TEXT, 0, 0, 0, 0, 0, 0, values, lo, hi}
#define TN(n, values, lo, hi) {n, FLEET_TEXT, 1, 0, 0, 0, 0, 0, values, lo, hi}
#define END_ {NULL, 0, 0, 0, 0, 0, 0, 0, NULL, 0, 0}
#define ID_ I_("id", 1, INT64_MAX)
#define UTIME_(n) I_(n, 0, UT_MAX)
#define STATE_ T_("state", "baseline|normal|watch|alert", 0, 0)

static const struct fleet_col passages_rules[] = {
    ID_, I_("vehicle_id", INT64_MIN, INT64_MAX), UTIME_("utime"), I_("lane", -32768, 32767),
    RN("speed_mps", 0, 0, AMFI_STORE_MAX_SPEED_MPS), I_("n_axles", 0, 12), RN("gvw_kg", 0, -KG, KG),
    T_("status", "ok|gap|late|overload|multiple|invalid|error", 0, 0), T_("reason", NULL, 0, 0),
    RN("lambda", 1, 0, INFINITY), RN("residual_rms", 0, 0, INFINITY), TN("formulation", NULL, 1, 63),
    RN("solve_ms", 0, 0, INFINITY), T_("stored_at", NULL, 0, 0),
    RN("speed_given_mps", 0, 0, AMFI_STORE_MAX_SPEED_MPS), I_("speed_estimated", 0, 1),
    I_("n_vehicles", 1, 64), RN("quality", 0, 1, 1e9), RN("reference_gvw_kg", 0, 1000, 100000),
    RN("deck_c", 0, -60, 80), RN("f1_hz", 1, 0, 1000), RN("f1_comp_hz", 1, 0, 1000),
    RN("f1_zeta", 2, 0, 1), RN("f1_r2", 0, 0, 1), RN("gvw_comp_kg", 1, 0, KG), END_};
static const struct fleet_col axles_rules[] = {
    I_("passage_id", 1, INT64_MAX), I_("idx", 1, 12),
    RN("spacing_m", 1, 0, AMFI_STORE_MAX_SPACING_M), RN("load_kg", 0, -KG, KG), END_};
static const struct fleet_col indicators_rules[] = {
    ID_, UTIME_("utime"), I_("n", 0, INT32_MAX), RN("mean_kg", 0, -KG, KG),
    RN("std_kg", 0, 0, KG), RN("baseline_mean_kg", 1, 0, KG), RN("baseline_std_kg", 1, 0, KG),
    RN("std_ratio", 0, 0, 1e6), RN("p_value", 0, 0, 1), STATE_, END_};
static const struct fleet_col alerts_rules[] = {
    ID_, UTIME_("utime"), T_("level", "info|warning", 0, 0), T_("kind", NULL, 1, 31),
    T_("message", NULL, 0, 0), IN("indicator_id", INT64_MIN, INT64_MAX), I_("raised", 0, 1), END_};
static const struct fleet_col baseline_rules[] = {
    ID_, UTIME_("utime_set"), I_("n", 2, INT32_MAX), R_("mean_kg", 1, 0, KG), R_("std_kg", 1, 0, KG),
    T_("source", "auto|manual", 0, 0), T_("note", NULL, 0, 127), T_("set_at", NULL, 0, 0), END_};
static const struct fleet_col runs_rules[] = {
    ID_, T_("started_at", NULL, 0, 0), T_("version", NULL, 1, 63), T_("config_path", NULL, 1, 4096),
    END_};
static const struct fleet_col environment_rules[] = {
    ID_, UTIME_("utime"), R_("deck_c", 0, -60, 80), R_("air_c", 0, -60, 80),
    UTIME_("received_utime"), END_};
static const struct fleet_col scale_evals_rules[] = {
    ID_, UTIME_("utime"), T_("kind", "scale_shift|known_truck", 0, 0), I_("n", 0, INT32_MAX),
    RN("value", 1, 0, 100), RN("raw", 1, 0, 100), RN("deck_c", 0, -60, 80),
    RN("z", 0, -1e6, 1e6), RN("cusum", 0, 0, 1e6), RN("h", 0, 0, 1e6), STATE_, END_};

const struct fleet_table fleet_tables[] = {
    {"passages",
     "id, vehicle_id, utime, lane, speed_mps, n_axles, gvw_kg, status, reason, lambda, "
     "residual_rms, formulation, solve_ms, stored_at, speed_given_mps, speed_estimated, "
     "n_vehicles, quality, reference_gvw_kg, deck_c, f1_hz, f1_comp_hz, f1_zeta, f1_r2, gvw_comp_kg",
     passages_rules, axles_rules, 14,
     "axles", "passage_id, idx, spacing_m, load_kg", "passage_id"},
    {"indicators",
     "id, utime, n, mean_kg, std_kg, baseline_mean_kg, baseline_std_kg, std_ratio, p_value, state",
     indicators_rules, NULL, 10, NULL, NULL, NULL},
    {"alerts", "id, utime, level, kind, message, indicator_id, raised", alerts_rules, NULL, 7,
     NULL, NULL, NULL},
    {"baseline", "id, utime_set, n, mean_kg, std_kg, source, note, set_at", baseline_rules, NULL, 8,
     NULL, NULL, NULL},
    {"runs", "id, started_at, version, config_path", runs_rules, NULL, 4, NULL, NULL, NULL},
    /* central version 5 */
    {"environment", "id, utime, deck_c, air_c, received_utime", environment_rules, NULL, 5, NULL,
     NULL, NULL},
    {"scale_evals", "id, utime, kind, n, value, raw, deck_c, z, cusum, h, state",
     scale_evals_rules, NULL, 11, NULL, NULL, NULL},
};
const int fleet_n_tables = (int)(sizeof fleet_tables / sizeof fleet_tables[0]);

/* s[0..len) is valid UTF-8 without a NUL byte. */
static int utf8_ok(const unsigned char *s, int len)
{
    for (int i = 0; i < len;) {
        unsigned c = s[i];
        int n = c < 0x80 ? 0 : (c & 0xe0) == 0xc0 && c >= 0xc2 ? 1 : (c & 0xf0) == 0xe0 ? 2
              : (c & 0xf8) == 0xf0 && c <= 0xf4 ? 3 : -1;
        if (c == 0 || n < 0 || i + n >= len) return 0;
        for (int k = 1; k <= n; k++)
            if ((s[i + k] & 0xc0) != 0x80) return 0;
        /* overlong 3/4-byte forms, surrogates, beyond U+10FFFF */
        if ((n == 2 && ((c == 0xe0 && s[i + 1] < 0xa0) || (c == 0xed && s[i + 1] >= 0xa0)))
            || (n == 3 && ((c == 0xf0 && s[i + 1] < 0x90) || (c == 0xf4 && s[i + 1] >= 0x90))))
            return 0;
        i += n + 1;
    }
    return 1;
}

const char *fleet_col_problem(const struct fleet_col *c, int type, int64_t i, double r,
                              const char *text, int len, char *msg, size_t msglen)
{
    static const char *const names[] = {"?", "an integer", "a real", "text", "a blob", "NULL"};
    const char *want = c->type == FLEET_INT ? "an integer" : c->type == FLEET_REAL ? "a number" : "text";
    if (type == 5) {
        if (c->null_ok) return NULL;
        snprintf(msg, msglen, "NULL, but it must be %s", want);
        return msg;
    }
    int ok_type = c->type == FLEET_INT ? type == 1 : c->type == FLEET_REAL ? type == 1 || type == 2
                                                                            : type == 3;
    if (!ok_type) {
        snprintf(msg, msglen, "%s, but it must be %s", type >= 1 && type <= 5 ? names[type] : names[0], want);
        return msg;
    }
    if (c->type == FLEET_INT) {
        if (i < c->ilo || i > c->ihi) {
            snprintf(msg, msglen, "%lld is not in [%lld, %lld]", (long long)i, (long long)c->ilo,
                     (long long)c->ihi);
            return msg;
        }
        return NULL;
    }
    if (c->type == FLEET_REAL) {
        double x = type == 1 ? (double)i : r;
        if (!isfinite(x) || ((c->open & 1) ? !(x > c->lo) : !(x >= c->lo))
            || ((c->open & 2) ? !(x < c->hi) : !(x <= c->hi))) {
            snprintf(msg, msglen, "%.17g is not in %c%.17g, %.17g%c", x, (c->open & 1) ? '(' : '[',
                     c->lo, c->hi, (c->open & 2) ? ')' : ']');
            return msg;
        }
        return NULL;
    }
    if (len < c->min_len || (c->max_len && len > c->max_len)) {
        snprintf(msg, msglen, "text of %d bytes, not %d..%d", len, c->min_len,
                 c->max_len ? c->max_len : INT32_MAX);
        return msg;
    }
    if (!utf8_ok((const unsigned char *)text, len)) {
        snprintf(msg, msglen, "text that is not valid UTF-8 (or holds a NUL byte)");
        return msg;
    }
    if (c->values) {
        size_t n = (size_t)len;
        for (const char *v = c->values; *v;) {
            const char *bar = strchr(v, '|');
            size_t k = bar ? (size_t)(bar - v) : strlen(v);
            if (k == n && memcmp(v, text, n) == 0) return NULL;
            v += k + (bar != NULL);
        }
        snprintf(msg, msglen, "'%.40s' is not one of %s", text, c->values);
        /* the value shown may hold control characters: made '?' */
        for (char *p = msg; *p; p++)
            if ((unsigned char)*p < 0x20) *p = '?';
        return msg;
    }
    return NULL;
}
