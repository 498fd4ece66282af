/*
 * store.c: amfid's SQLite store (see store.h for the contract and
 * docs/schema.md for the schema as people see it).
 *
 * Workload: one writer, a few passages per second at most, each in its own
 * transaction (BEGIN IMMEDIATE, one passage row, up to 12 axle rows,
 * COMMIT); readers in other processes through WAL. Every statement the
 * handle runs more than once is prepared at open (SQLITE_PREPARE_PERSISTENT)
 * and reset after use; no SQL is ever built from data, only bound.
 *
 * The schema is versioned with PRAGMA user_version. `migrations` below is
 * the ordered list of steps from version 0 (an empty file); open applies the
 * missing ones in one IMMEDIATE transaction, recording each in the
 * schema_migrations table, so a failed migration leaves the file as it was
 * and two processes opening a new file at once cannot both migrate. A step,
 * once released, is never edited: a change is a new step.
 *
 * Errors follow SQLite's own style: one `rc` (an amfi status, 0 ok) chained
 * through each function with `if (rc == 0)`, the first failure writing the
 * message; a transaction started is rolled back on any failure.
 */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <sqlite3.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "store.h"

/* The schema's CHECK constraints spell these numbers out. */
_Static_assert(AMFI_MAX_AXLES == 12,
               "schema v1 checks idx/n_axles against 12: add a migration");
_Static_assert(AMFI_STORE_APPLICATION_ID == 1095583305,
               "schema v1 sets PRAGMA application_id = 1095583305");

/* ---- schema --------------------------------------------------------------- */

/* Version 1, exactly as docs/schema.md shows it (tests/test_store.c compares
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

typedef struct migration {
    int version;             /* user_version once applied, 1, 2, ... */
    const char *description; /* recorded in schema_migrations */
    const char *sql;         /* one or more statements */
} migration;

static const migration migrations[] = {
    {1, "passages, axles, truth, truth_axles, indicators, alerts, baseline, "
        "meta; views daily_trend, window_trend, passage_errors", schema_v1},
};
#define N_MIGRATIONS ((int)(sizeof migrations / sizeof migrations[0]))
_Static_assert(sizeof migrations / sizeof migrations[0]
                   == AMFI_STORE_SCHEMA_VERSION,
               "one migration per schema version");

/* ---- prepared statements ------------------------------------------------ */

enum {
    ST_BEGIN,
    ST_COMMIT,
    ST_ROLLBACK,
    ST_INS_PASSAGE,
    ST_INS_AXLE,
    ST_INS_TRUTH,
    ST_INS_TRUTH_AXLE,
    ST_INS_INDICATOR,
    ST_INS_ALERT,
    ST_GET_BASELINE,
    ST_INS_BASELINE,
    ST_RECENT_OK,
    ST_META_GET,
    ST_META_SET,
    ST_INTEGRITY,
    ST_FK_CHECK,
    N_STMT
};

static const char *const stmt_sql[N_STMT] = {
    [ST_BEGIN] = "BEGIN IMMEDIATE",
    [ST_COMMIT] = "COMMIT",
    [ST_ROLLBACK] = "ROLLBACK",
    [ST_INS_PASSAGE] =
        "INSERT INTO passages (vehicle_id, utime, lane, speed_mps, n_axles, "
        "gvw_kg, status, reason, lambda, residual_rms, formulation, solve_ms) "
        "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12)",
    [ST_INS_AXLE] =
        "INSERT INTO axles (passage_id, idx, spacing_m, load_kg) "
        "VALUES (?1, ?2, ?3, ?4)",
    [ST_INS_TRUTH] =
        "INSERT INTO truth (vehicle_id, utime, gvw_kg, n_axles, speed_true_mps) "
        "VALUES (?1, ?2, ?3, ?4, ?5)",
    [ST_INS_TRUTH_AXLE] =
        "INSERT INTO truth_axles (truth_id, idx, load_kg, mean_force_N) "
        "VALUES (?1, ?2, ?3, ?4)",
    [ST_INS_INDICATOR] =
        "INSERT INTO indicators (utime, n, mean_kg, std_kg, baseline_mean_kg, "
        "baseline_std_kg, std_ratio, p_value, state) "
        "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9)",
    [ST_INS_ALERT] =
        "INSERT INTO alerts (utime, level, kind, message, indicator_id, raised) "
        "VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
    [ST_GET_BASELINE] =
        "SELECT id, utime_set, n, mean_kg, std_kg, source, note "
        "FROM baseline ORDER BY id DESC LIMIT 1",
    [ST_INS_BASELINE] =
        "INSERT INTO baseline (utime_set, n, mean_kg, std_kg, source, note) "
        "VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
    /* index passages_status_utime, walked backwards */
    [ST_RECENT_OK] =
        "SELECT id, gvw_kg FROM passages WHERE status = 'ok' "
        "ORDER BY utime DESC, id DESC LIMIT ?1",
    [ST_META_GET] = "SELECT rowid, value FROM meta WHERE key = ?1",
    [ST_META_SET] =
        "INSERT INTO meta (key, value) VALUES (?1, ?2) "
        "ON CONFLICT (key) DO UPDATE SET value = excluded.value, "
        "updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now')",
    [ST_INTEGRITY] = "PRAGMA integrity_check(100)",
    [ST_FK_CHECK] = "PRAGMA foreign_key_check",
};

struct amfi_store {
    sqlite3 *db;
    int readonly;                /* opened with amfi_store_open_readonly */
    sqlite3_stmt *st[N_STMT];    /* prepared at open, reset after each use */
    char path[256];              /* for messages (truncated) */
};

/* ---- messages ------------------------------------------------------------- */

const char *amfi_store_strerror(int status)
{
    switch (status) {
    case AMFI_STORE_EDB: return "database error";
    case AMFI_STORE_ECORRUPT: return "damaged database or row";
    case AMFI_STORE_ESCHEMA: return "not an amfi store, or unknown schema version";
    default: return amfi_strerror(status);
    }
}

/* Writes the message into err (when there is room) and returns status. */
static int fail(char *err, size_t errlen, int status, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

static int fail(char *err, size_t errlen, int status, const char *fmt, ...)
{
    if (err && errlen > 0) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, errlen, fmt, ap);
        va_end(ap);
    }
    return status;
}

/* At most 40 bytes of s, control bytes as '?', "..." when cut: a string
 * from the caller or the file shown in a one-line message. */
static const char *excerpt(const char *s, char out[48])
{
    size_t k = 0;
    for (; s[k] && k < 40; k++)
        out[k] = ((unsigned char)s[k] < 0x20 || s[k] == 0x7f) ? '?' : s[k];
    if (s[k]) {
        memcpy(out + k, "...", 3);
        k += 3;
    }
    out[k] = '\0';
    return out;
}

/* SQLite result code (extended) to amfi status. */
static int status_of(int sqlite_rc)
{
    switch (sqlite_rc & 0xff) {
    case SQLITE_NOMEM: return AMFI_ENOMEM;
    case SQLITE_CONSTRAINT:
    case SQLITE_MISMATCH:
    case SQLITE_TOOBIG: return AMFI_EINVAL;
    case SQLITE_CORRUPT:
    case SQLITE_NOTADB: return AMFI_STORE_ECORRUPT;
    default: return AMFI_STORE_EDB;
    }
}

/* "WHAT: sqlite's message" for a failed call on s->db. */
static int db_fail(amfi_store *s, int sqlite_rc, const char *what, char *err,
                   size_t errlen)
{
    int ext = sqlite3_extended_errcode(s->db);
    const char *msg = sqlite3_errmsg(s->db);
    if ((sqlite_rc & 0xff) == SQLITE_BUSY)
        return fail(err, errlen, AMFI_STORE_EDB,
                    "%s: database is locked (another writer held it for "
                    "more than %d ms)", what, AMFI_STORE_BUSY_TIMEOUT_MS);
    if ((sqlite_rc & 0xff) == SQLITE_NOTADB)
        return fail(err, errlen, AMFI_STORE_ECORRUPT,
                    "%s: not an SQLite database (%s)", what, msg);
    if (ext == SQLITE_CONSTRAINT_FOREIGNKEY)
        return fail(err, errlen, AMFI_EINVAL,
                    "%s: refers to a row that does not exist (%s)", what, msg);
    return fail(err, errlen, status_of(sqlite_rc), "%s: %s", what, msg);
}

/* ---- argument checks ----------------------------------------------------- */

/* Closed or half-open range of a number. */
typedef struct range {
    double lo, hi;   /* bounds; hi may be HUGE_VAL (no upper bound) */
    int lo_open;     /* 1: x > lo, 0: x >= lo */
    const char *unit;
} range;

static const range R_SPEED = {0.0, AMFI_STORE_MAX_SPEED_MPS, 0, "m/s"};
static const range R_SPEED_POS = {0.0, AMFI_STORE_MAX_SPEED_MPS, 1, "m/s"};
static const range R_SPACING = {0.0, AMFI_STORE_MAX_SPACING_M, 1, "m"};
static const range R_KG = {-AMFI_STORE_MAX_KG, AMFI_STORE_MAX_KG, 0, "kg"};
static const range R_KG_POS = {0.0, AMFI_STORE_MAX_KG, 1, "kg"};
static const range R_KG_NONNEG = {0.0, AMFI_STORE_MAX_KG, 0, "kg"};
static const range R_FORCE = {-AMFI_STORE_MAX_FORCE_N, AMFI_STORE_MAX_FORCE_N, 0, "N"};
static const range R_POS = {0.0, HUGE_VAL, 1, ""};
static const range R_NONNEG = {0.0, HUGE_VAL, 0, ""};
static const range R_MS = {0.0, HUGE_VAL, 0, "ms"};
static const range R_RATIO = {0.0, 1e6, 0, ""};
static const range R_PROB = {0.0, 1.0, 0, ""};

static int in_range(double x, const range *rg)
{
    return (rg->lo_open ? x > rg->lo : x >= rg->lo) && x <= rg->hi;
}

/* "NAME: X UNIT is out of range ..." (x finite, outside rg). */
static int range_fail(const char *prefix, const char *name, double x,
                      const range *rg, int status, char *err, size_t errlen)
{
    const char *sp = rg->unit[0] ? " " : "";
    if (isinf(rg->hi))
        return fail(err, errlen, status, "%s%s: %g%s%s must be %s %g%s%s",
                    prefix, name, x, sp, rg->unit, rg->lo_open ? ">" : ">=",
                    rg->lo, sp, rg->unit);
    return fail(err, errlen, status, "%s%s: %g%s%s is out of range %c%g, %g]%s%s",
                prefix, name, x, sp, rg->unit, rg->lo_open ? '(' : '[',
                rg->lo, rg->hi, sp, rg->unit);
}

/* x is NaN (unknown, stored as NULL) or finite and within rg. */
static int check_num(const char *name, double x, const range *rg, char *err,
                     size_t errlen)
{
    if (isnan(x))
        return 0;
    if (isinf(x))
        return fail(err, errlen, AMFI_EINVAL, "%s: %g is not a finite number",
                    name, x);
    if (!in_range(x, rg))
        return range_fail("", name, x, rg, AMFI_EINVAL, err, errlen);
    return 0;
}

/* A number that must be known (not NaN). */
static int check_known(const char *name, double x, const range *rg, char *err,
                       size_t errlen)
{
    if (isnan(x))
        return fail(err, errlen, AMFI_EINVAL, "%s: NaN, a value is needed",
                    name);
    return check_num(name, x, rg, err, errlen);
}

static int check_utime(const char *name, int64_t t, char *err, size_t errlen)
{
    if (t < 0 || t > AMFI_STORE_MAX_UTIME)
        return fail(err, errlen, AMFI_EINVAL,
                    "%s: %lld us is out of range [0, %lld] (1970 .. 9999 UTC)",
                    name, (long long)t, (long long)AMFI_STORE_MAX_UTIME);
    return 0;
}

/* Length of the valid UTF-8 prefix of s; *bad set when s holds a control
 * byte (< 0x20, 0x7f) or invalid UTF-8 (overlong, surrogate, > U+10FFFF). */
static size_t utf8_scan(const unsigned char *s, size_t n, int *bad)
{
    size_t k = 0;
    *bad = 0;
    while (k < n) {
        unsigned c = s[k];
        int len;
        unsigned cp;
        if (c < 0x80) {
            if (c < 0x20 || c == 0x7f) {
                *bad = 1;
                return k;
            }
            k++;
            continue;
        }
        if (c >= 0xc2 && c <= 0xdf) { len = 2; cp = c & 0x1f; }
        else if (c >= 0xe0 && c <= 0xef) { len = 3; cp = c & 0x0f; }
        else if (c >= 0xf0 && c <= 0xf4) { len = 4; cp = c & 0x07; }
        else { *bad = 1; return k; }
        if (k + (size_t)len > n) { *bad = 1; return k; }
        for (int j = 1; j < len; j++) {
            unsigned cc = s[k + (size_t)j];
            if ((cc & 0xc0) != 0x80) { *bad = 1; return k; }
            cp = (cp << 6) | (cc & 0x3f);
        }
        if ((len == 3 && (cp < 0x800 || (cp >= 0xd800 && cp <= 0xdfff)))
            || (len == 4 && (cp < 0x10000 || cp > 0x10ffff))) {
            *bad = 1;
            return k;
        }
        k += (size_t)len;
    }
    return k;
}

/* s: valid UTF-8 text of min .. max bytes without control characters. */
static int check_text(const char *name, const char *s, size_t min, size_t max,
                      char *err, size_t errlen)
{
    char ex[48];
    int bad;
    if (!s)
        return fail(err, errlen, AMFI_EINVAL, "%s: NULL", name);
    size_t n = strlen(s);
    if (n < min)
        return fail(err, errlen, AMFI_EINVAL, "%s: empty", name);
    if (n > max)
        return fail(err, errlen, AMFI_EINVAL,
                    "%s: %zu bytes, at most %zu allowed ('%s')", name, n, max,
                    excerpt(s, ex));
    size_t ok = utf8_scan((const unsigned char *)s, n, &bad);
    if (bad)
        return fail(err, errlen, AMFI_EINVAL,
                    "%s: control character or invalid UTF-8 at byte %zu ('%s')",
                    name, ok, excerpt(s, ex));
    return 0;
}

/* s is one of list (NULL-terminated); `shown` lists them for the message. */
static int check_enum(const char *name, const char *s,
                      const char *const *list, const char *shown, char *err,
                      size_t errlen)
{
    char ex[48];
    if (!s)
        return fail(err, errlen, AMFI_EINVAL, "%s: NULL (one of %s)", name,
                    shown);
    for (; *list; list++)
        if (strcmp(s, *list) == 0)
            return 0;
    return fail(err, errlen, AMFI_EINVAL, "%s: '%s' is not one of %s", name,
                excerpt(s, ex), shown);
}

/* s: 1 .. max bytes, each in `allowed` or alphanumeric (lower case only
 * when lower != 0). */
static int check_token(const char *name, const char *s, size_t max,
                       const char *allowed, int lower, char *err,
                       size_t errlen)
{
    char ex[48];
    if (!s || !*s)
        return fail(err, errlen, AMFI_EINVAL, "%s: empty", name);
    size_t n = strlen(s);
    if (n > max)
        return fail(err, errlen, AMFI_EINVAL, "%s: '%s' is longer than %zu bytes",
                    name, excerpt(s, ex), max);
    for (size_t k = 0; k < n; k++) {
        unsigned char c = (unsigned char)s[k];
        int ok = (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9')
                 || (!lower && c >= 'A' && c <= 'Z')
                 || (c != 0 && strchr(allowed, c) != NULL);
        if (!ok)
            return fail(err, errlen, AMFI_EINVAL,
                        "%s: '%s' has a character outside [%s%s]", name,
                        excerpt(s, ex), lower ? "a-z0-9" : "A-Za-z0-9", allowed);
    }
    return 0;
}

static const char *const statuses[] = {"ok", "gap", "late", "overload",
                                       "multiple", "invalid", "error", NULL};
static const char *const states[] = {"baseline", "normal", "watch", "alert",
                                     NULL};
static const char *const levels[] = {"info", "warning", NULL};
static const char *const sources[] = {"auto", "manual", NULL};

static int check_handle(const amfi_store *s, int write, char *err,
                        size_t errlen)
{
    if (!s)
        return fail(err, errlen, AMFI_EINVAL, "store: handle is NULL");
    if (write && s->readonly)
        return fail(err, errlen, AMFI_STORE_EDB,
                    "%s: store opened read-only", s->path);
    return 0;
}

static int check_passage(const amfi_passage_row *r, char *err, size_t errlen)
{
    char name[48];
    int rc = 0;
    if (!r)
        return fail(err, errlen, AMFI_EINVAL, "passages: row is NULL");
    rc = check_enum("passages.status", r->status, statuses,
                    AMFI_STORE_STATUSES, err, errlen);
    if (rc == 0)
        rc = check_utime("passages.utime", r->utime, err, errlen);
    if (rc == 0 && (r->lane < -32768 || r->lane > 32767))
        rc = fail(err, errlen, AMFI_EINVAL,
                  "passages.lane: %d is out of range [-32768, 32767]", r->lane);
    if (rc == 0 && (r->n_axles < 0 || r->n_axles > AMFI_MAX_AXLES))
        rc = fail(err, errlen, AMFI_EINVAL,
                  "passages.n_axles: %d is out of range [0, %d]", r->n_axles,
                  AMFI_MAX_AXLES);
    if (rc == 0)
        rc = check_num("passages.speed_mps", r->speed_mps, &R_SPEED, err, errlen);
    if (rc == 0)
        rc = check_num("passages.gvw_kg", r->gvw_kg, &R_KG, err, errlen);
    if (rc == 0)
        rc = check_num("passages.lambda", r->lambda, &R_POS, err, errlen);
    if (rc == 0)
        rc = check_num("passages.residual_rms", r->residual_rms, &R_NONNEG,
                       err, errlen);
    if (rc == 0)
        rc = check_num("passages.solve_ms", r->solve_ms, &R_MS, err, errlen);
    for (int k = 0; rc == 0 && k < r->n_axles - 1; k++) {
        snprintf(name, sizeof name, "passages: spacing_m[%d]", k);
        rc = check_num(name, r->spacing_m[k], &R_SPACING, err, errlen);
    }
    for (int k = 0; rc == 0 && k < r->n_axles; k++) {
        snprintf(name, sizeof name, "passages: axle_kg[%d]", k);
        rc = check_num(name, r->axle_kg[k], &R_KG, err, errlen);
    }
    if (rc == 0 && r->reason)
        rc = check_text("passages.reason", r->reason, 0, AMFI_STORE_REASON_MAX,
                        err, errlen);
    if (rc == 0 && r->formulation)
        rc = check_text("passages.formulation", r->formulation, 1, 63, err,
                        errlen);
    if (rc != 0 || strcmp(r->status, "ok") != 0)
        return rc;
    /* status ok: a solved passage with everything known */
    if (r->n_axles < 1)
        return fail(err, errlen, AMFI_EINVAL,
                    "passages: status ok needs n_axles >= 1 (got 0)");
    rc = check_known("passages: status ok: gvw_kg", r->gvw_kg, &R_KG_POS, err,
                     errlen);
    if (rc == 0)
        rc = check_known("passages: status ok: speed_mps", r->speed_mps,
                         &R_SPEED_POS, err, errlen);
    for (int k = 0; rc == 0 && k < r->n_axles - 1; k++) {
        snprintf(name, sizeof name, "passages: status ok: spacing_m[%d]", k);
        rc = check_known(name, r->spacing_m[k], &R_SPACING, err, errlen);
    }
    for (int k = 0; rc == 0 && k < r->n_axles; k++) {
        snprintf(name, sizeof name, "passages: status ok: axle_kg[%d]", k);
        rc = check_known(name, r->axle_kg[k], &R_KG, err, errlen);
    }
    return rc;
}

/* ---- statement helpers --------------------------------------------------- */

static int bind_real(sqlite3_stmt *st, int i, double x)
{
    return isnan(x) ? sqlite3_bind_null(st, i) : sqlite3_bind_double(st, i, x);
}

/* The strings are the caller's and live until the statement is reset and
 * its bindings cleared (done before returning), hence SQLITE_STATIC. */
static int bind_text(sqlite3_stmt *st, int i, const char *t)
{
    return t ? sqlite3_bind_text(st, i, t, -1, SQLITE_STATIC)
             : sqlite3_bind_null(st, i);
}

static void done_with(sqlite3_stmt *st)
{
    sqlite3_reset(st);
    sqlite3_clear_bindings(st);
}

/* Step statement `which` (its values bound, sqlite_rc the bindings'
 * status) to completion: no row expected. Resets it. */
static int run(amfi_store *s, int which, int sqlite_rc, const char *what,
               char *err, size_t errlen)
{
    sqlite3_stmt *st = s->st[which];
    int rc = 0;
    if (sqlite_rc == SQLITE_OK)
        sqlite_rc = sqlite3_step(st);
    else
        rc = fail(err, errlen, status_of(sqlite_rc), "%s: binding: %s", what,
                  sqlite3_errstr(sqlite_rc));
    if (rc == 0 && sqlite_rc != SQLITE_DONE)
        rc = sqlite_rc == SQLITE_ROW
                 ? fail(err, errlen, AMFI_STORE_EDB, "%s: unexpected row", what)
                 : db_fail(s, sqlite_rc, what, err, errlen);
    done_with(st);
    return rc;
}

static int begin(amfi_store *s, char *err, size_t errlen)
{
    return run(s, ST_BEGIN, SQLITE_OK, "begin transaction", err, errlen);
}

static int commit(amfi_store *s, char *err, size_t errlen)
{
    return run(s, ST_COMMIT, SQLITE_OK, "commit", err, errlen);
}

/* Undo the open transaction, if any (after a failure; keeps its message). */
static void rollback(amfi_store *s)
{
    if (!sqlite3_get_autocommit(s->db)) {
        sqlite3_step(s->st[ST_ROLLBACK]);
        sqlite3_reset(s->st[ST_ROLLBACK]);
    }
}

/* One-off statement (open and migration only): run sql, every row ignored
 * except that the first row's first column goes to *ival / text (when not
 * NULL). */
static int one_off(amfi_store *s, const char *sql, const char *what,
                   int64_t *ival, char *text, size_t textlen, char *err,
                   size_t errlen)
{
    sqlite3_stmt *st = NULL;
    int src = sqlite3_prepare_v2(s->db, sql, -1, &st, NULL);
    int rc = 0, first = 1;
    if (src != SQLITE_OK)
        rc = db_fail(s, src, what, err, errlen);
    while (rc == 0 && (src = sqlite3_step(st)) == SQLITE_ROW) {
        if (first && ival)
            *ival = sqlite3_column_int64(st, 0);
        if (first && text && textlen > 0) {
            const unsigned char *t = sqlite3_column_text(st, 0);
            snprintf(text, textlen, "%s", t ? (const char *)t : "");
        }
        first = 0;
    }
    if (rc == 0 && src != SQLITE_DONE)
        rc = db_fail(s, src, what, err, errlen);
    sqlite3_finalize(st);
    return rc;
}

/* ---- open / close --------------------------------------------------------- */

/* Finalize, optionally tidy (optimize, checkpoint), close, free. */
static void destroy(amfi_store *s, int tidy)
{
    if (!s)
        return;
    for (int k = 0; k < N_STMT; k++)
        sqlite3_finalize(s->st[k]);
    if (s->db && tidy && !s->readonly) {
        sqlite3_exec(s->db, "PRAGMA optimize", NULL, NULL, NULL);
        sqlite3_wal_checkpoint_v2(s->db, NULL, SQLITE_CHECKPOINT_TRUNCATE,
                                  NULL, NULL);
    }
    sqlite3_close(s->db);
    free(s);
}

void amfi_store_close(amfi_store *s) { destroy(s, 1); }

struct sqlite3 *amfi_store_db(amfi_store *s) { return s ? s->db : NULL; }

/* Is this file an amfi store this code can use? *version gets its
 * user_version. Reads only: a refused file is left untouched. */
static int check_identity(amfi_store *s, int *version, char *err,
                          size_t errlen)
{
    int64_t app = 0, ver = 0, objects = 0;
    int rc = one_off(s, "PRAGMA application_id", s->path, &app, NULL, 0, err,
                     errlen);
    if (rc == 0)
        rc = one_off(s, "PRAGMA user_version", s->path, &ver, NULL, 0, err,
                     errlen);
    if (rc == 0)
        rc = one_off(s, "SELECT count(*) FROM sqlite_schema", s->path,
                     &objects, NULL, 0, err, errlen);
    if (rc != 0)
        return rc;
    if (app != 0 && app != AMFI_STORE_APPLICATION_ID)
        return fail(err, errlen, AMFI_STORE_ESCHEMA,
                    "%s: not an amfi store (application_id 0x%08llx)", s->path,
                    (unsigned long long)(uint32_t)app);
    if (ver > AMFI_STORE_SCHEMA_VERSION)
        return fail(err, errlen, AMFI_STORE_ESCHEMA,
                    "%s: schema version %lld is newer than this program's %d: "
                    "use a newer amfi (the file was not changed)",
                    s->path, (long long)ver, AMFI_STORE_SCHEMA_VERSION);
    if (ver < 0 || (ver == 0 && objects > 0) || (ver > 0 && app == 0))
        return fail(err, errlen, AMFI_STORE_ESCHEMA,
                    "%s: not an amfi store (user_version %lld, application_id "
                    "0x%08llx, %lld schema objects)", s->path, (long long)ver,
                    (unsigned long long)(uint32_t)app, (long long)objects);
    *version = (int)ver;
    return 0;
}

/* Apply the missing migrations in one IMMEDIATE transaction. */
static int migrate(amfi_store *s, char *err, size_t errlen)
{
    int64_t ver = 0;
    char what[320];
    int rc = one_off(s, "BEGIN IMMEDIATE", "migration: begin", NULL, NULL, 0,
                     err, errlen);
    /* again under the write lock: another process may have been first */
    if (rc == 0)
        rc = one_off(s, "PRAGMA user_version", s->path, &ver, NULL, 0, err,
                     errlen);
    if (rc == 0 && ver > AMFI_STORE_SCHEMA_VERSION)
        rc = fail(err, errlen, AMFI_STORE_ESCHEMA,
                  "%s: schema version %lld is newer than this program's %d",
                  s->path, (long long)ver, AMFI_STORE_SCHEMA_VERSION);
    for (int k = 0; rc == 0 && k < N_MIGRATIONS; k++) {
        const migration *m = &migrations[k];
        char *emsg = NULL;
        sqlite3_stmt *st = NULL;
        char pragma[48];
        if (m->version <= ver)
            continue;
        snprintf(what, sizeof what, "%s: migration to version %d", s->path,
                 m->version);
        int src = sqlite3_exec(s->db, m->sql, NULL, NULL, &emsg);
        if (src != SQLITE_OK)
            rc = fail(err, errlen, status_of(src) == AMFI_EINVAL
                                       ? AMFI_STORE_EDB : status_of(src),
                      "%s: %s", what, emsg ? emsg : sqlite3_errstr(src));
        sqlite3_free(emsg);
        if (rc == 0) {
            src = sqlite3_prepare_v2(s->db,
                                     "INSERT INTO schema_migrations "
                                     "(version, description) VALUES (?1, ?2)",
                                     -1, &st, NULL);
            if (src == SQLITE_OK)
                src = sqlite3_bind_int(st, 1, m->version);
            if (src == SQLITE_OK)
                src = sqlite3_bind_text(st, 2, m->description, -1, SQLITE_STATIC);
            if (src == SQLITE_OK)
                src = sqlite3_step(st) == SQLITE_DONE ? SQLITE_OK
                                                      : sqlite3_errcode(s->db);
            if (src != SQLITE_OK)
                rc = db_fail(s, src, what, err, errlen);
            sqlite3_finalize(st);
        }
        /* PRAGMA takes no parameters; the number is our own constant */
        snprintf(pragma, sizeof pragma, "PRAGMA user_version = %d", m->version);
        if (rc == 0)
            rc = one_off(s, pragma, what, NULL, NULL, 0, err, errlen);
    }
    if (rc == 0)
        rc = one_off(s, "COMMIT", "migration: commit", NULL, NULL, 0, err,
                     errlen);
    if (rc != 0 && !sqlite3_get_autocommit(s->db))
        sqlite3_exec(s->db, "ROLLBACK", NULL, NULL, NULL);
    return rc;
}

static int open_store(const char *path, int readonly, int sync_full,
                      amfi_store **out, char *err, size_t errlen)
{
    amfi_store *s = NULL;
    int version = 0, src, rc = 0;
    char mode[16] = "";
    struct stat sb;

    if (!out)
        return fail(err, errlen, AMFI_EINVAL, "store: out is NULL");
    *out = NULL;
    if (!path || !*path)
        return fail(err, errlen, AMFI_EINVAL, "store: empty path");
    s = calloc(1, sizeof *s);
    if (!s)
        return fail(err, errlen, AMFI_ENOMEM, "%s: out of memory", path);
    snprintf(s->path, sizeof s->path, "%s", path);
    s->readonly = readonly;
    /* SQLite's "unable to open database file" does not say why */
    if (readonly && stat(path, &sb) != 0)
        rc = fail(err, errlen, AMFI_STORE_EDB, "%s: %s", s->path,
                  strerror(errno));
    else if (readonly && !S_ISREG(sb.st_mode))
        rc = fail(err, errlen, AMFI_STORE_EDB, "%s: not a regular file", s->path);
    if (rc == 0) {
        int flags = readonly ? SQLITE_OPEN_READONLY
                             : SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE;
        src = sqlite3_open_v2(path, &s->db, flags | SQLITE_OPEN_NOMUTEX, NULL);
        if (src != SQLITE_OK)
            rc = fail(err, errlen, status_of(src), "%s: cannot open: %s",
                      s->path, s->db ? sqlite3_errmsg(s->db) : sqlite3_errstr(src));
    }
    if (rc == 0) {
        sqlite3_extended_result_codes(s->db, 1);
        sqlite3_busy_timeout(s->db, AMFI_STORE_BUSY_TIMEOUT_MS);
        rc = check_identity(s, &version, err, errlen);
    }
    if (rc == 0 && readonly && version != AMFI_STORE_SCHEMA_VERSION)
        rc = fail(err, errlen, AMFI_STORE_ESCHEMA,
                  version == 0
                      ? "%s: empty database, not an amfi store yet "
                        "(schema version %d; amfid creates it)"
                      : "%s: schema version %d is older than this program's %d: "
                        "open it read-write once (amfid does at start-up)",
                  s->path, version, AMFI_STORE_SCHEMA_VERSION);
    if (rc == 0 && readonly)
        rc = one_off(s, "PRAGMA query_only = ON", s->path, NULL, NULL, 0, err,
                     errlen);
    if (rc == 0 && !readonly) {
        rc = one_off(s, "PRAGMA journal_mode = WAL", s->path, NULL, mode,
                     sizeof mode, err, errlen);
        if (rc == 0 && strcmp(mode, "wal") != 0 && strcmp(mode, "memory") != 0)
            rc = fail(err, errlen, AMFI_STORE_EDB,
                      "%s: cannot switch to WAL mode (journal_mode is '%s')",
                      s->path, mode);
    }
    if (rc == 0 && !readonly)
        rc = one_off(s, sync_full ? "PRAGMA synchronous = FULL"
                                  : "PRAGMA synchronous = NORMAL",
                     s->path, NULL, NULL, 0, err, errlen);
    if (rc == 0) {
        int64_t fk = 0;
        rc = one_off(s, "PRAGMA foreign_keys = ON", s->path, NULL, NULL, 0, err,
                     errlen);
        if (rc == 0)
            rc = one_off(s, "PRAGMA foreign_keys", s->path, &fk, NULL, 0, err,
                         errlen);
        if (rc == 0 && fk != 1)
            rc = fail(err, errlen, AMFI_STORE_EDB,
                      "%s: SQLite built without foreign keys", s->path);
    }
    if (rc == 0 && !readonly && version < AMFI_STORE_SCHEMA_VERSION)
        rc = migrate(s, err, errlen);
    for (int k = 0; rc == 0 && k < N_STMT; k++) {
        src = sqlite3_prepare_v3(s->db, stmt_sql[k], -1,
                                 SQLITE_PREPARE_PERSISTENT, &s->st[k], NULL);
        if (src != SQLITE_OK)
            rc = db_fail(s, src, s->path, err, errlen);
    }
    if (rc != 0) {
        destroy(s, 0);
        return rc;
    }
    *out = s;
    return 0;
}

int amfi_store_open(const char *path, int sync_full, amfi_store **out,
                    char *err, size_t errlen)
{
    return open_store(path, 0, sync_full, out, err, errlen);
}

int amfi_store_open_readonly(const char *path, amfi_store **out, char *err,
                             size_t errlen)
{
    return open_store(path, 1, 0, out, err, errlen);
}

/* ---- writes --------------------------------------------------------------- */

int amfi_store_add_passage(amfi_store *s, const amfi_passage_row *r,
                           int64_t *id, char *err, size_t errlen)
{
    int64_t pid = 0;
    int rc = check_handle(s, 1, err, errlen);
    if (rc == 0)
        rc = check_passage(r, err, errlen);
    if (rc == 0)
        rc = begin(s, err, errlen);
    if (rc == 0) {
        sqlite3_stmt *st = s->st[ST_INS_PASSAGE];
        int b = sqlite3_bind_int64(st, 1, r->vehicle_id);
        if (b == SQLITE_OK) b = sqlite3_bind_int64(st, 2, r->utime);
        if (b == SQLITE_OK) b = sqlite3_bind_int(st, 3, r->lane);
        if (b == SQLITE_OK) b = bind_real(st, 4, r->speed_mps);
        if (b == SQLITE_OK) b = sqlite3_bind_int(st, 5, r->n_axles);
        if (b == SQLITE_OK) b = bind_real(st, 6, r->gvw_kg);
        if (b == SQLITE_OK) b = bind_text(st, 7, r->status);
        if (b == SQLITE_OK) b = bind_text(st, 8, r->reason ? r->reason : "");
        if (b == SQLITE_OK) b = bind_real(st, 9, r->lambda);
        if (b == SQLITE_OK) b = bind_real(st, 10, r->residual_rms);
        if (b == SQLITE_OK) b = bind_text(st, 11, r->formulation);
        if (b == SQLITE_OK) b = bind_real(st, 12, r->solve_ms);
        rc = run(s, ST_INS_PASSAGE, b, "passages: insert", err, errlen);
        if (rc == 0)
            pid = sqlite3_last_insert_rowid(s->db);
    }
    for (int k = 0; rc == 0 && k < r->n_axles; k++) {
        sqlite3_stmt *st = s->st[ST_INS_AXLE];
        int b = sqlite3_bind_int64(st, 1, pid);
        if (b == SQLITE_OK) b = sqlite3_bind_int(st, 2, k + 1);
        if (b == SQLITE_OK)
            b = k == 0 ? sqlite3_bind_null(st, 3)
                       : bind_real(st, 3, r->spacing_m[k - 1]);
        if (b == SQLITE_OK) b = bind_real(st, 4, r->axle_kg[k]);
        rc = run(s, ST_INS_AXLE, b, "axles: insert", err, errlen);
    }
    if (rc == 0)
        rc = commit(s, err, errlen);
    if (rc != 0 && s)
        rollback(s);
    if (rc == 0 && id)
        *id = pid;
    return rc;
}

int amfi_store_add_truth(amfi_store *s, int64_t vehicle_id, int64_t utime,
                         double gvw_kg, int n_axles, const double *axle_kg,
                         const double *mean_force_N, double speed_true_mps,
                         char *err, size_t errlen)
{
    char name[48];
    int64_t tid = 0;
    int rc = check_handle(s, 1, err, errlen);
    if (rc == 0)
        rc = check_utime("truth.utime", utime, err, errlen);
    if (rc == 0)
        rc = check_known("truth.gvw_kg", gvw_kg, &R_KG_POS, err, errlen);
    if (rc == 0 && (n_axles < 1 || n_axles > AMFI_MAX_AXLES))
        rc = fail(err, errlen, AMFI_EINVAL,
                  "truth.n_axles: %d is out of range [1, %d]", n_axles,
                  AMFI_MAX_AXLES);
    if (rc == 0 && !axle_kg)
        rc = fail(err, errlen, AMFI_EINVAL, "truth: axle_kg is NULL");
    for (int k = 0; rc == 0 && k < n_axles; k++) {
        snprintf(name, sizeof name, "truth: axle_kg[%d]", k);
        rc = check_known(name, axle_kg[k], &R_KG_POS, err, errlen);
    }
    for (int k = 0; rc == 0 && mean_force_N && k < n_axles; k++) {
        snprintf(name, sizeof name, "truth: mean_force_N[%d]", k);
        rc = check_num(name, mean_force_N[k], &R_FORCE, err, errlen);
    }
    if (rc == 0)
        rc = check_num("truth.speed_true_mps", speed_true_mps, &R_SPEED_POS,
                       err, errlen);
    if (rc == 0)
        rc = begin(s, err, errlen);
    if (rc == 0) {
        sqlite3_stmt *st = s->st[ST_INS_TRUTH];
        int b = sqlite3_bind_int64(st, 1, vehicle_id);
        if (b == SQLITE_OK) b = sqlite3_bind_int64(st, 2, utime);
        if (b == SQLITE_OK) b = sqlite3_bind_double(st, 3, gvw_kg);
        if (b == SQLITE_OK) b = sqlite3_bind_int(st, 4, n_axles);
        if (b == SQLITE_OK) b = bind_real(st, 5, speed_true_mps);
        rc = run(s, ST_INS_TRUTH, b, "truth: insert", err, errlen);
        if (rc == 0)
            tid = sqlite3_last_insert_rowid(s->db);
    }
    for (int k = 0; rc == 0 && k < n_axles; k++) {
        sqlite3_stmt *st = s->st[ST_INS_TRUTH_AXLE];
        int b = sqlite3_bind_int64(st, 1, tid);
        if (b == SQLITE_OK) b = sqlite3_bind_int(st, 2, k + 1);
        if (b == SQLITE_OK) b = sqlite3_bind_double(st, 3, axle_kg[k]);
        if (b == SQLITE_OK)
            b = bind_real(st, 4, mean_force_N ? mean_force_N[k] : NAN);
        rc = run(s, ST_INS_TRUTH_AXLE, b, "truth_axles: insert", err, errlen);
    }
    if (rc == 0)
        rc = commit(s, err, errlen);
    if (rc != 0 && s)
        rollback(s);
    return rc;
}

int amfi_store_add_indicator(amfi_store *s, const amfi_indicator_row *r,
                             int64_t *id, char *err, size_t errlen)
{
    int rc = check_handle(s, 1, err, errlen);
    if (rc == 0 && !r)
        rc = fail(err, errlen, AMFI_EINVAL, "indicators: row is NULL");
    if (rc == 0)
        rc = check_utime("indicators.utime", r->utime, err, errlen);
    if (rc == 0 && r->n < 0)
        rc = fail(err, errlen, AMFI_EINVAL, "indicators.n: %d must be >= 0",
                  r->n);
    if (rc == 0)
        rc = check_num("indicators.mean_kg", r->mean_kg, &R_KG, err, errlen);
    if (rc == 0)
        rc = check_num("indicators.std_kg", r->std_kg, &R_KG_NONNEG, err, errlen);
    if (rc == 0)
        rc = check_num("indicators.baseline_mean_kg", r->baseline_mean_kg,
                       &R_KG_POS, err, errlen);
    if (rc == 0)
        rc = check_num("indicators.baseline_std_kg", r->baseline_std_kg,
                       &R_KG_POS, err, errlen);
    if (rc == 0)
        rc = check_num("indicators.std_ratio", r->std_ratio, &R_RATIO, err,
                       errlen);
    if (rc == 0)
        rc = check_num("indicators.p_value", r->p_value, &R_PROB, err, errlen);
    if (rc == 0)
        rc = check_enum("indicators.state", r->state, states,
                        "baseline, normal, watch, alert", err, errlen);
    if (rc == 0) {
        sqlite3_stmt *st = s->st[ST_INS_INDICATOR];
        int b = sqlite3_bind_int64(st, 1, r->utime);
        if (b == SQLITE_OK) b = sqlite3_bind_int(st, 2, r->n);
        if (b == SQLITE_OK) b = bind_real(st, 3, r->mean_kg);
        if (b == SQLITE_OK) b = bind_real(st, 4, r->std_kg);
        if (b == SQLITE_OK) b = bind_real(st, 5, r->baseline_mean_kg);
        if (b == SQLITE_OK) b = bind_real(st, 6, r->baseline_std_kg);
        if (b == SQLITE_OK) b = bind_real(st, 7, r->std_ratio);
        if (b == SQLITE_OK) b = bind_real(st, 8, r->p_value);
        if (b == SQLITE_OK) b = bind_text(st, 9, r->state);
        rc = run(s, ST_INS_INDICATOR, b, "indicators: insert", err, errlen);
    }
    if (rc == 0 && id)
        *id = sqlite3_last_insert_rowid(s->db);
    return rc;
}

int amfi_store_add_alert(amfi_store *s, int64_t utime, const char *level,
                         const char *kind, const char *message,
                         int64_t indicator_id, int raised, int64_t *id,
                         char *err, size_t errlen)
{
    char what[64];
    int rc = check_handle(s, 1, err, errlen);
    if (rc == 0)
        rc = check_utime("alerts.utime", utime, err, errlen);
    if (rc == 0)
        rc = check_enum("alerts.level", level, levels, "info, warning", err,
                        errlen);
    if (rc == 0)
        rc = check_token("alerts.kind", kind, 31, "_", 1, err, errlen);
    if (rc == 0)
        rc = check_text("alerts.message", message, 1, AMFI_STORE_REASON_MAX,
                        err, errlen);
    if (rc == 0 && raised != 0 && raised != 1)
        rc = fail(err, errlen, AMFI_EINVAL,
                  "alerts.raised: %d is neither 1 (raised) nor 0 (cleared)",
                  raised);
    if (rc == 0) {
        sqlite3_stmt *st = s->st[ST_INS_ALERT];
        int b = sqlite3_bind_int64(st, 1, utime);
        if (b == SQLITE_OK) b = bind_text(st, 2, level);
        if (b == SQLITE_OK) b = bind_text(st, 3, kind);
        if (b == SQLITE_OK) b = bind_text(st, 4, message);
        if (b == SQLITE_OK)
            b = indicator_id > 0 ? sqlite3_bind_int64(st, 5, indicator_id)
                                 : sqlite3_bind_null(st, 5);
        if (b == SQLITE_OK) b = sqlite3_bind_int(st, 6, raised);
        snprintf(what, sizeof what, "alerts: insert (indicator_id %lld)",
                 (long long)indicator_id);
        rc = run(s, ST_INS_ALERT, b, what, err, errlen);
    }
    if (rc == 0 && id)
        *id = sqlite3_last_insert_rowid(s->db);
    return rc;
}

static int check_baseline(const amfi_baseline *b, char *err, size_t errlen)
{
    int rc = 0;
    if (!b)
        return fail(err, errlen, AMFI_EINVAL, "baseline: NULL");
    rc = check_utime("baseline.utime_set", b->utime_set, err, errlen);
    if (rc == 0 && b->n < 2)
        rc = fail(err, errlen, AMFI_EINVAL,
                  "baseline.n: %d, a STD needs at least 2 passages", b->n);
    if (rc == 0)
        rc = check_known("baseline.mean_kg", b->mean_kg, &R_KG_POS, err, errlen);
    if (rc == 0)
        rc = check_known("baseline.std_kg", b->std_kg, &R_KG_POS, err, errlen);
    if (rc == 0 && !memchr(b->source, '\0', sizeof b->source))
        rc = fail(err, errlen, AMFI_EINVAL, "baseline.source: not terminated");
    if (rc == 0)
        rc = check_enum("baseline.source", b->source, sources, "auto, manual",
                        err, errlen);
    if (rc == 0 && !memchr(b->note, '\0', sizeof b->note))
        rc = fail(err, errlen, AMFI_EINVAL,
                  "baseline.note: not terminated within %zu bytes",
                  sizeof b->note);
    if (rc == 0)
        rc = check_text("baseline.note", b->note, 0, sizeof b->note - 1, err,
                        errlen);
    return rc;
}

int amfi_store_set_baseline(amfi_store *s, const amfi_baseline *b, char *err,
                            size_t errlen)
{
    int rc = check_handle(s, 1, err, errlen);
    if (rc == 0)
        rc = check_baseline(b, err, errlen);
    if (rc == 0) {
        sqlite3_stmt *st = s->st[ST_INS_BASELINE];
        int q = sqlite3_bind_int64(st, 1, b->utime_set);
        if (q == SQLITE_OK) q = sqlite3_bind_int(st, 2, b->n);
        if (q == SQLITE_OK) q = sqlite3_bind_double(st, 3, b->mean_kg);
        if (q == SQLITE_OK) q = sqlite3_bind_double(st, 4, b->std_kg);
        if (q == SQLITE_OK) q = bind_text(st, 5, b->source);
        if (q == SQLITE_OK) q = bind_text(st, 6, b->note);
        rc = run(s, ST_INS_BASELINE, q, "baseline: insert", err, errlen);
    }
    return rc;
}

static int check_meta_key(const char *key, char *err, size_t errlen)
{
    return check_token("meta.key", key, AMFI_STORE_META_KEY_MAX, "_.-", 0, err,
                       errlen);
}

int amfi_store_meta_set(amfi_store *s, const char *key, const char *val,
                        char *err, size_t errlen)
{
    int rc = check_handle(s, 1, err, errlen);
    if (rc == 0)
        rc = check_meta_key(key, err, errlen);
    if (rc == 0)
        rc = check_text("meta.value", val, 0, AMFI_STORE_META_VALUE_MAX, err,
                        errlen);
    if (rc == 0) {
        sqlite3_stmt *st = s->st[ST_META_SET];
        int b = bind_text(st, 1, key);
        if (b == SQLITE_OK) b = bind_text(st, 2, val);
        rc = run(s, ST_META_SET, b, "meta: set", err, errlen);
    }
    return rc;
}

/* ---- reads: every value checked --------------------------------------- */

/* Where a value read back came from, for the message. */
typedef struct origin {
    const char *table;
    int64_t rowid;
} origin;

static int corrupt(const origin *o, sqlite3_stmt *st, int col, char *err,
                   size_t errlen, const char *problem)
{
    return fail(err, errlen, AMFI_STORE_ECORRUPT, "%s row %lld: %s %s",
                o->table, (long long)o->rowid, sqlite3_column_name(st, col),
                problem);
}

static const char *type_name(int t)
{
    switch (t) {
    case SQLITE_INTEGER: return "an integer";
    case SQLITE_FLOAT: return "a real";
    case SQLITE_TEXT: return "text";
    case SQLITE_BLOB: return "a blob";
    default: return "NULL";
    }
}

/* A number (integer or real storage) within rg; NULL is refused. */
static int read_real(sqlite3_stmt *st, int col, const range *rg,
                     const origin *o, double *out, char *err, size_t errlen)
{
    char problem[96];
    int t = sqlite3_column_type(st, col);
    if (t != SQLITE_FLOAT && t != SQLITE_INTEGER) {
        snprintf(problem, sizeof problem, "is %s, expected a number",
                 type_name(t));
        return corrupt(o, st, col, err, errlen, problem);
    }
    double x = sqlite3_column_double(st, col);
    if (!isfinite(x) || !in_range(x, rg)) {
        char name[96];
        snprintf(name, sizeof name, "%s row %lld: %s", o->table,
                 (long long)o->rowid, sqlite3_column_name(st, col));
        if (!isfinite(x))
            return fail(err, errlen, AMFI_STORE_ECORRUPT,
                        "%s: %g is not finite", name, x);
        return range_fail("", name, x, rg, AMFI_STORE_ECORRUPT, err, errlen);
    }
    *out = x;
    return 0;
}

/* An integer (integer storage) in lo .. hi. */
static int read_int(sqlite3_stmt *st, int col, int64_t lo, int64_t hi,
                    const origin *o, int64_t *out, char *err, size_t errlen)
{
    char problem[96];
    int t = sqlite3_column_type(st, col);
    if (t != SQLITE_INTEGER) {
        snprintf(problem, sizeof problem, "is %s, expected an integer",
                 type_name(t));
        return corrupt(o, st, col, err, errlen, problem);
    }
    int64_t v = sqlite3_column_int64(st, col);
    if (v < lo || v > hi) {
        snprintf(problem, sizeof problem, "= %lld is out of range [%lld, %lld]",
                 (long long)v, (long long)lo, (long long)hi);
        return corrupt(o, st, col, err, errlen, problem);
    }
    *out = v;
    return 0;
}

/* Text of at most max bytes, valid UTF-8 without control characters, into
 * buf (buflen > max is the caller's business; a value longer than
 * buflen − 1 but within max is AMFI_EINVAL: the buffer, not the row). */
static int read_text(sqlite3_stmt *st, int col, size_t max, const origin *o,
                     char *buf, size_t buflen, char *err, size_t errlen)
{
    char problem[96];
    int t = sqlite3_column_type(st, col), bad;
    if (t != SQLITE_TEXT) {
        snprintf(problem, sizeof problem, "is %s, expected text", type_name(t));
        return corrupt(o, st, col, err, errlen, problem);
    }
    const unsigned char *txt = sqlite3_column_text(st, col);
    size_t n = (size_t)sqlite3_column_bytes(st, col);
    if (!txt)
        return fail(err, errlen, AMFI_ENOMEM, "%s row %lld: out of memory",
                    o->table, (long long)o->rowid);
    if (n > max) {
        snprintf(problem, sizeof problem, "is %zu bytes, at most %zu allowed",
                 n, max);
        return corrupt(o, st, col, err, errlen, problem);
    }
    utf8_scan(txt, n, &bad);
    if (bad || memchr(txt, '\0', n))
        return corrupt(o, st, col, err, errlen,
                       "holds a control character or invalid UTF-8");
    if (n >= buflen)
        return fail(err, errlen, AMFI_EINVAL,
                    "%s row %lld: %s is %zu bytes, the buffer holds %zu",
                    o->table, (long long)o->rowid,
                    sqlite3_column_name(st, col), n,
                    buflen > 0 ? buflen - 1 : 0);
    memcpy(buf, txt, n);
    buf[n] = '\0';
    return 0;
}

int amfi_store_get_baseline(amfi_store *s, amfi_baseline *b, int *found,
                            char *err, size_t errlen)
{
    amfi_baseline tmp;
    int64_t v = 0;
    int rc = check_handle(s, 0, err, errlen);
    if (rc == 0 && (!b || !found))
        rc = fail(err, errlen, AMFI_EINVAL, "baseline: output is NULL");
    if (rc != 0)
        return rc;
    *found = 0;
    memset(&tmp, 0, sizeof tmp);
    sqlite3_stmt *st = s->st[ST_GET_BASELINE];
    int src = sqlite3_step(st);
    if (src == SQLITE_ROW) {
        origin o = {"baseline", sqlite3_column_int64(st, 0)};
        rc = read_int(st, 1, 0, AMFI_STORE_MAX_UTIME, &o, &tmp.utime_set, err,
                      errlen);
        if (rc == 0)
            rc = read_int(st, 2, 2, INT_MAX, &o, &v, err, errlen);
        tmp.n = (int)v;
        if (rc == 0)
            rc = read_real(st, 3, &R_KG_POS, &o, &tmp.mean_kg, err, errlen);
        if (rc == 0)
            rc = read_real(st, 4, &R_KG_POS, &o, &tmp.std_kg, err, errlen);
        if (rc == 0)
            rc = read_text(st, 5, sizeof tmp.source - 1, &o, tmp.source,
                           sizeof tmp.source, err, errlen);
        if (rc == 0 && check_enum("source", tmp.source, sources, "", NULL, 0))
            rc = corrupt(&o, st, 5, err, errlen, "is neither auto nor manual");
        if (rc == 0)
            rc = read_text(st, 6, sizeof tmp.note - 1, &o, tmp.note,
                           sizeof tmp.note, err, errlen);
        if (rc == 0) {
            *b = tmp;
            *found = 1;
        }
    } else if (src != SQLITE_DONE) {
        rc = db_fail(s, src, "baseline: read", err, errlen);
    }
    sqlite3_reset(st);
    return rc;
}

int amfi_store_recent_ok_gvw(amfi_store *s, int max, double *gvw, int *n,
                             char *err, size_t errlen)
{
    int rc = check_handle(s, 0, err, errlen), src = SQLITE_OK, count = 0;
    if (rc == 0 && (!gvw || !n))
        rc = fail(err, errlen, AMFI_EINVAL, "recent ok GVW: output is NULL");
    if (rc == 0 && max < 1)
        rc = fail(err, errlen, AMFI_EINVAL, "recent ok GVW: max %d must be >= 1",
                  max);
    if (rc != 0)
        return rc;
    *n = 0;
    sqlite3_stmt *st = s->st[ST_RECENT_OK];
    src = sqlite3_bind_int(st, 1, max);
    /* newest first into gvw[0 ..], reversed below */
    while (rc == 0 && src == SQLITE_OK && (src = sqlite3_step(st)) == SQLITE_ROW) {
        origin o = {"passages", sqlite3_column_int64(st, 0)};
        if (count >= max)
            rc = fail(err, errlen, AMFI_STORE_EDB,
                      "recent ok GVW: more rows than the LIMIT");
        else
            rc = read_real(st, 1, &R_KG_POS, &o, &gvw[count], err, errlen);
        if (rc == 0)
            count++;
        src = SQLITE_OK;
    }
    if (rc == 0 && src != SQLITE_DONE)
        rc = db_fail(s, src, "passages: read recent ok GVW", err, errlen);
    done_with(st);
    if (rc != 0)
        return rc;
    for (int i = 0, j = count - 1; i < j; i++, j--) {
        double t = gvw[i];
        gvw[i] = gvw[j];
        gvw[j] = t;
    }
    *n = count;
    return 0;
}

int amfi_store_meta_get(amfi_store *s, const char *key, char *val,
                        size_t vallen, int *found, char *err, size_t errlen)
{
    int rc = check_handle(s, 0, err, errlen);
    if (rc == 0 && (!val || vallen == 0 || !found))
        rc = fail(err, errlen, AMFI_EINVAL, "meta: output is NULL or empty");
    if (rc == 0)
        rc = check_meta_key(key, err, errlen);
    if (rc != 0)
        return rc;
    *found = 0;
    val[0] = '\0';
    sqlite3_stmt *st = s->st[ST_META_GET];
    int src = bind_text(st, 1, key);
    if (src == SQLITE_OK)
        src = sqlite3_step(st);
    if (src == SQLITE_ROW) {
        origin o = {"meta", sqlite3_column_int64(st, 0)};
        rc = read_text(st, 1, AMFI_STORE_META_VALUE_MAX, &o, val, vallen, err,
                       errlen);
        if (rc == 0)
            *found = 1;
        else
            val[0] = '\0';
    } else if (src != SQLITE_DONE) {
        rc = db_fail(s, src, "meta: read", err, errlen);
    }
    done_with(st);
    return rc;
}

/* ---- maintenance -------------------------------------------------------- */

/* Append "; " (unless first) and piece to result (len > 0), truncating. */
static void append(char *result, size_t len, const char *piece)
{
    size_t used = strlen(result);
    if (used + 1 >= len)
        return;
    snprintf(result + used, len - used, "%s%s", used ? "; " : "", piece);
}

int amfi_store_integrity_check(amfi_store *s, char *result, size_t len,
                               char *err, size_t errlen)
{
    char piece[256];
    int rc = check_handle(s, 0, err, errlen), src, clean = 1;
    if (rc == 0 && (!result || len == 0))
        rc = fail(err, errlen, AMFI_EINVAL, "integrity check: result is NULL");
    if (rc != 0)
        return rc;
    result[0] = '\0';
    sqlite3_stmt *st = s->st[ST_INTEGRITY];
    while ((src = sqlite3_step(st)) == SQLITE_ROW) {
        const unsigned char *t = sqlite3_column_text(st, 0);
        if (t && strcmp((const char *)t, "ok") == 0)
            continue;
        clean = 0;
        append(result, len, t ? (const char *)t : "(no message)");
    }
    if (src != SQLITE_DONE)
        rc = db_fail(s, src, "integrity check", err, errlen);
    sqlite3_reset(st);
    st = s->st[ST_FK_CHECK];
    /* rows: table, rowid (NULL for WITHOUT ROWID), parent, constraint */
    while (rc == 0 && (src = sqlite3_step(st)) == SQLITE_ROW) {
        const unsigned char *tab = sqlite3_column_text(st, 0);
        const unsigned char *par = sqlite3_column_text(st, 2);
        clean = 0;
        if (sqlite3_column_type(st, 1) == SQLITE_NULL)
            snprintf(piece, sizeof piece, "foreign key: a %s row refers to a "
                     "missing %s row", tab ? (const char *)tab : "?",
                     par ? (const char *)par : "?");
        else
            snprintf(piece, sizeof piece, "foreign key: %s row %lld refers to "
                     "a missing %s row", tab ? (const char *)tab : "?",
                     (long long)sqlite3_column_int64(st, 1),
                     par ? (const char *)par : "?");
        append(result, len, piece);
    }
    if (rc == 0 && src != SQLITE_DONE)
        rc = db_fail(s, src, "foreign key check", err, errlen);
    sqlite3_reset(st);
    if (rc != 0) {
        /* too damaged to check: the message is the result too */
        if (err && errlen > 0)
            snprintf(result, len, "%s", err);
        else
            snprintf(result, len, "%s", amfi_store_strerror(rc));
        return rc;
    }
    if (clean)
        snprintf(result, len, "ok");
    return 0;
}
