/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_open.c: opening and closing a store: the file's identity, the
 * migrations (store_schema.c) applied in one IMMEDIATE transaction, the
 * pragmas, and every statement the handle runs more than once, prepared at
 * open (SQLITE_PREPARE_PERSISTENT) and reset after use; no SQL is ever
 * built from data, only bound. Also the messages shared by the store's
 * files. The caller's thread; the handle is its state.
 *
 * The schema is versioned with PRAGMA user_version; open applies the
 * missing migrations recording each in the schema_migrations table, so a
 * failed migration leaves the file as it was and two processes opening a
 * new file at once cannot both migrate.
 *
 * Errors follow SQLite's own style: one `rc` (an amfi status, 0 ok) chained
 * through each function with `if (rc == 0)`, the first failure writing the
 * message; a transaction started is rolled back on any failure.
 */
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <sys/stat.h>

#include "store_internal.h"

/* ---- prepared statements ------------------------------------------------ */

static const char *const stmt_sql[N_STMT] = {
    [ST_BEGIN] = "BEGIN IMMEDIATE",
    [ST_COMMIT] = "COMMIT",
    [ST_ROLLBACK] = "ROLLBACK",
    [ST_INS_AXLE] =
        "INSERT INTO axles (passage_id, idx, spacing_m, load_kg) "
        "VALUES (?1, ?2, ?3, ?4)",
    [ST_INS_TRUTH] =
        "INSERT INTO truth (vehicle_id, utime, gvw_kg, n_axles, speed_true_mps) "
        "VALUES (?1, ?2, ?3, ?4, ?5)",
    [ST_INS_TRUTH_AXLE] =
        "INSERT INTO truth_axles (truth_id, idx, load_kg, mean_force_N) "
        "VALUES (?1, ?2, ?3, ?4)",
    [ST_GET_BASELINE] =
        "SELECT id, utime_set, n, mean_kg, std_kg, source, note "
        "FROM baseline ORDER BY id DESC LIMIT 1",
    [ST_INS_BASELINE] =
        "INSERT INTO baseline (utime_set, n, mean_kg, std_kg, source, note) "
        "VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
    /* index passages_status_utime, walked backwards */
    [ST_RECENT_OK] =
        "SELECT id, gvw_kg, gvw_comp_kg FROM passages WHERE status = 'ok' "
        "ORDER BY utime DESC, id DESC LIMIT ?1",
    [ST_META_GET] = "SELECT rowid, value FROM meta WHERE key = ?1",
    [ST_META_SET] =
        "INSERT INTO meta (key, value) VALUES (?1, ?2) "
        "ON CONFLICT (key) DO UPDATE SET value = excluded.value, "
        "updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now')",
    [ST_INTEGRITY] = "PRAGMA integrity_check(100)",
    [ST_FK_CHECK] = "PRAGMA foreign_key_check",
    [ST_INS_RUN] = "INSERT INTO runs (version, config_path) VALUES (?1, ?2)",
    [ST_ALERT_LAST_OF_KIND] =
        "SELECT id, raised FROM alerts WHERE kind = ?1 ORDER BY id DESC LIMIT 1",
    [ST_COUNT_PASSAGES] = "SELECT count(*) FROM passages",
    [ST_COUNT_INDICATORS] = "SELECT count(*) FROM indicators",
    [ST_COUNT_ALERTS] = "SELECT count(*) FROM alerts",
    [ST_COUNT_TRUTH] = "SELECT count(*) FROM truth",
    [ST_PASSAGE_SPAN] = "SELECT count(*), min(utime), max(utime) FROM passages",
    [ST_PASSAGE_BY_STATUS] = "SELECT status, count(*) FROM passages GROUP BY status",
    [ST_ALL_OK_GVW] = "SELECT id, gvw_kg FROM passages WHERE status = 'ok'",
    [ST_ALL_FED_GVW] = "SELECT id, gvw_comp_kg FROM passages WHERE status = 'ok' "
                       "AND gvw_comp_kg IS NOT NULL",
    /* the columns of the two alert queries are read by one function */
    [ST_RECENT_ALERTS] =
        "SELECT id, utime, level, kind, raised, indicator_id, message "
        "FROM alerts ORDER BY utime DESC, id DESC LIMIT ?1",
    /* open now: the newest event of each kind is a raise */
    [ST_OPEN_ALERTS] =
        "SELECT a.id, a.utime, a.level, a.kind, a.raised, a.indicator_id, "
        "a.message FROM alerts AS a WHERE a.raised = 1 AND a.id = (SELECT b.id "
        "FROM alerts AS b WHERE b.kind = a.kind ORDER BY b.utime DESC, b.id DESC "
        "LIMIT 1) ORDER BY a.utime",
    [ST_GVW_ERRORS] = "SELECT passage_id, status, gvw_error_pct FROM passage_errors",
};

/* The inserts of the tables written from a row: from the column table
 * (store_rows.c). */
static const char *const stmt_table[N_STMT] = {
    [ST_INS_PASSAGE] = "passages",
    [ST_INS_INDICATOR] = "indicators",
    [ST_INS_ALERT] = "alerts",
};
/* The reads of a table's row struct: "SELECT id, <its columns> FROM ..." */
static const struct {
    const char *table, *tail;
} stmt_read[N_STMT] = {
    [ST_RECENT_INDICATORS] = {"indicators", "ORDER BY utime DESC, id DESC LIMIT ?1"},
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

int st_fail(char *err, size_t errlen, int status, const char *fmt, ...)
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
const char *st_excerpt(const char *s, char out[48])
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
int st_status_of(int sqlite_rc)
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
int st_db_fail(amfi_store *s, int sqlite_rc, const char *what, char *err,
                   size_t errlen)
{
    int ext = sqlite3_extended_errcode(s->db);
    const char *msg = sqlite3_errmsg(s->db);
    if ((sqlite_rc & 0xff) == SQLITE_BUSY)
        return st_fail(err, errlen, AMFI_STORE_EDB,
                    "%s: database is locked (another writer held it for "
                    "more than %d ms)", what, AMFI_STORE_BUSY_TIMEOUT_MS);
    if ((sqlite_rc & 0xff) == SQLITE_NOTADB)
        return st_fail(err, errlen, AMFI_STORE_ECORRUPT,
                    "%s: not an SQLite database (%s)", what, msg);
    if (ext == SQLITE_CONSTRAINT_FOREIGNKEY)
        return st_fail(err, errlen, AMFI_EINVAL,
                    "%s: refers to a row that does not exist (%s)", what, msg);
    return st_fail(err, errlen, st_status_of(sqlite_rc), "%s: %s", what, msg);
}

/* ---- open / close --------------------------------------------------------- */

/* Finalize, optionally tidy (optimize, checkpoint), close, free. */
static void destroy(amfi_store *s, int tidy)
{
    if (!s)
        return;
    for (int k = 0; k < N_STMT; k++)
        sqlite3_finalize(s->st[k]);
    st_raw_free(s);
    if (s->db && tidy && !s->readonly) {
        sqlite3_exec(s->db, "PRAGMA optimize", NULL, NULL, NULL);
        sqlite3_wal_checkpoint_v2(s->db, NULL, SQLITE_CHECKPOINT_TRUNCATE,
                                  NULL, NULL);
    }
    sqlite3_close(s->db);
    free(s);
}

void amfi_store_close(amfi_store *s) { destroy(s, 1); }

void amfi_store_remove(const char *path)
{
    char p[4200];
    unlink(path);
    snprintf(p, sizeof p, "%s-wal", path);
    unlink(p);
    snprintf(p, sizeof p, "%s-shm", path);
    unlink(p);
}

/* Is this file an amfi store this code can use? *version gets its
 * user_version. Reads only: a refused file is left untouched. */
static int check_identity(amfi_store *s, int *version, char *err,
                          size_t errlen)
{
    int64_t app = 0, ver = 0, objects = 0;
    int rc = st_one_off(s, "PRAGMA application_id", s->path, &app, NULL, 0, err,
                     errlen);
    if (rc == 0)
        rc = st_one_off(s, "PRAGMA user_version", s->path, &ver, NULL, 0, err,
                     errlen);
    if (rc == 0)
        rc = st_one_off(s, "SELECT count(*) FROM sqlite_schema", s->path,
                     &objects, NULL, 0, err, errlen);
    if (rc != 0)
        return rc;
    if (app != 0 && app != AMFI_STORE_APPLICATION_ID)
        return st_fail(err, errlen, AMFI_STORE_ESCHEMA,
                    "%s: not an amfi store (application_id 0x%08llx)", s->path,
                    (unsigned long long)(uint32_t)app);
    if (ver > AMFI_STORE_SCHEMA_VERSION)
        return st_fail(err, errlen, AMFI_STORE_ESCHEMA,
                    "%s: schema version %lld is newer than this program's %d: "
                    "use a newer amfi (the file was not changed)",
                    s->path, (long long)ver, AMFI_STORE_SCHEMA_VERSION);
    if (ver < 0 || (ver == 0 && objects > 0) || (ver > 0 && app == 0))
        return st_fail(err, errlen, AMFI_STORE_ESCHEMA,
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
    int rc = st_one_off(s, "BEGIN IMMEDIATE", "migration: begin", NULL, NULL, 0,
                     err, errlen);
    /* again under the write lock: another process may have been first */
    if (rc == 0)
        rc = st_one_off(s, "PRAGMA user_version", s->path, &ver, NULL, 0, err,
                     errlen);
    if (rc == 0 && ver > AMFI_STORE_SCHEMA_VERSION)
        rc = st_fail(err, errlen, AMFI_STORE_ESCHEMA,
                  "%s: schema version %lld is newer than this program's %d",
                  s->path, (long long)ver, AMFI_STORE_SCHEMA_VERSION);
    for (int k = 0; rc == 0 && k < st_n_migrations; k++) {
        const st_migration *m = &st_migrations[k];
        char *emsg = NULL;
        sqlite3_stmt *st = NULL;
        char pragma[48];
        if (m->version <= ver)
            continue;
        snprintf(what, sizeof what, "%s: migration to version %d", s->path,
                 m->version);
        int src = sqlite3_exec(s->db, m->sql, NULL, NULL, &emsg);
        if (src != SQLITE_OK)
            rc = st_fail(err, errlen, st_status_of(src) == AMFI_EINVAL
                                       ? AMFI_STORE_EDB : st_status_of(src),
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
                rc = st_db_fail(s, src, what, err, errlen);
            sqlite3_finalize(st);
        }
        /* PRAGMA takes no parameters; the number is our own constant */
        snprintf(pragma, sizeof pragma, "PRAGMA user_version = %d", m->version);
        if (rc == 0)
            rc = st_one_off(s, pragma, what, NULL, NULL, 0, err, errlen);
    }
    if (rc == 0)
        rc = st_one_off(s, "COMMIT", "migration: commit", NULL, NULL, 0, err,
                     errlen);
    if (rc != 0 && !sqlite3_get_autocommit(s->db))
        sqlite3_exec(s->db, "ROLLBACK", NULL, NULL, NULL);
    return rc;
}

/* The connection's defences, before anything is read from the file:
 * defensive mode (no writable_schema, no journal_mode OFF, no writes that
 * could corrupt the file), an untrusted schema (a view or trigger in the
 * file may only call functions SQLite marks innocuous, so no
 * load_extension, fts3_tokenizer or the like), no extension loading.
 * `foreign` (a store this process did not write: amfi-report's readers and
 * its --set-baseline): triggers off too, an amfi store has none; 2 (a
 * reader of rows, amfi-sync: tables only): views off and query_only too.
 * Each setting is read back: an SQLite that ignores one is refused. */
static int harden(amfi_store *s, int foreign, char *err, size_t errlen)
{
    static const struct {
        int op, want;
        const char *name;
    } set[] = {
        {SQLITE_DBCONFIG_DEFENSIVE, 1, "SQLITE_DBCONFIG_DEFENSIVE"},
        {SQLITE_DBCONFIG_TRUSTED_SCHEMA, 0, "SQLITE_DBCONFIG_TRUSTED_SCHEMA"},
        {SQLITE_DBCONFIG_ENABLE_LOAD_EXTENSION, 0, "SQLITE_DBCONFIG_ENABLE_LOAD_EXTENSION"},
        {SQLITE_DBCONFIG_ENABLE_TRIGGER, 0, "SQLITE_DBCONFIG_ENABLE_TRIGGER"},
        {SQLITE_DBCONFIG_ENABLE_VIEW, 0, "SQLITE_DBCONFIG_ENABLE_VIEW"},
    };
    for (size_t k = 0; k < sizeof set / sizeof set[0]; k++) {
        if ((set[k].op == SQLITE_DBCONFIG_ENABLE_TRIGGER && !foreign)
            || (set[k].op == SQLITE_DBCONFIG_ENABLE_VIEW && foreign < 2))
            continue;
        int got = -1;
        int src = sqlite3_db_config(s->db, set[k].op, set[k].want, &got);
        if (src != SQLITE_OK || got != set[k].want)
            return st_fail(err, errlen, AMFI_STORE_EDB, "%s: cannot set %s to %d (SQLite %s)",
                           s->path, set[k].name, set[k].want, sqlite3_libversion());
    }
    if (foreign >= 2) {
        char *emsg = NULL;
        if (sqlite3_exec(s->db, "PRAGMA query_only = ON", NULL, NULL, &emsg) != SQLITE_OK) {
            st_fail(err, errlen, AMFI_STORE_EDB, "%s: PRAGMA query_only: %s", s->path,
                    emsg ? emsg : "failed");
            sqlite3_free(emsg);
            return AMFI_STORE_EDB;
        }
    }
    return 0;
}

/* A store from elsewhere holding a trigger is refused: amfi's schema has
 * none, and one would run on the rows this program writes. */
static int no_trigger(amfi_store *s, char *err, size_t errlen)
{
    char name[128] = "", ex[48];
    int rc = st_one_off(s, "SELECT name FROM sqlite_schema WHERE type = 'trigger' LIMIT 1",
                        s->path, NULL, name, sizeof name, err, errlen);
    if (rc == 0 && name[0])
        rc = st_fail(err, errlen, AMFI_STORE_ESCHEMA,
                     "%s: not an amfi store: it holds trigger '%s' (amfi's schema has none; "
                     "the file was not changed)", s->path, st_excerpt(name, ex));
    return rc;
}

static int open_store(const char *path, int readonly, int foreign, int sync_full,
                      amfi_store **out, char *err, size_t errlen)
{
    amfi_store *s = NULL;
    int version = 0, src, rc = 0;
    char mode[16] = "";
    struct stat sb;

    if (!out)
        return st_fail(err, errlen, AMFI_EINVAL, "store: out is NULL");
    *out = NULL;
    if (!path || !*path)
        return st_fail(err, errlen, AMFI_EINVAL, "store: empty path");
    s = calloc(1, sizeof *s);
    if (!s)
        return st_fail(err, errlen, AMFI_ENOMEM, "%s: out of memory", path);
    snprintf(s->path, sizeof s->path, "%s", path);
    s->readonly = readonly;
    /* SQLite's "unable to open database file" does not say why */
    if (readonly && stat(path, &sb) != 0)
        rc = st_fail(err, errlen, AMFI_STORE_EDB, "%s: %s", s->path,
                  strerror(errno));
    else if (readonly && !S_ISREG(sb.st_mode))
        rc = st_fail(err, errlen, AMFI_STORE_EDB, "%s: not a regular file", s->path);
    if (rc == 0) {
        int flags = readonly ? SQLITE_OPEN_READONLY
                             : SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE;
        src = sqlite3_open_v2(path, &s->db, flags | SQLITE_OPEN_NOMUTEX, NULL);
        if (src != SQLITE_OK)
            rc = st_fail(err, errlen, st_status_of(src), "%s: cannot open: %s",
                      s->path, s->db ? sqlite3_errmsg(s->db) : sqlite3_errstr(src));
    }
    if (rc == 0) {
        sqlite3_extended_result_codes(s->db, 1);
        sqlite3_busy_timeout(s->db, AMFI_STORE_BUSY_TIMEOUT_MS);
        rc = harden(s, foreign, err, errlen);
    }
    if (rc == 0)
        rc = check_identity(s, &version, err, errlen);
    if (rc == 0 && foreign)
        rc = no_trigger(s, err, errlen);
    if (rc == 0 && readonly && version != AMFI_STORE_SCHEMA_VERSION)
        rc = st_fail(err, errlen, AMFI_STORE_ESCHEMA,
                  version == 0
                      ? "%s: empty database, not an amfi store yet "
                        "(schema version %d; amfid creates it)"
                      : "%s: schema version %d is older than this program's %d: "
                        "open it read-write once (amfid does at start-up)",
                  s->path, version, AMFI_STORE_SCHEMA_VERSION);
    if (rc == 0 && readonly)
        rc = st_one_off(s, "PRAGMA query_only = ON", s->path, NULL, NULL, 0, err,
                     errlen);
    if (rc == 0 && !readonly) {
        rc = st_one_off(s, "PRAGMA journal_mode = WAL", s->path, NULL, mode,
                     sizeof mode, err, errlen);
        if (rc == 0 && strcmp(mode, "wal") != 0 && strcmp(mode, "memory") != 0)
            rc = st_fail(err, errlen, AMFI_STORE_EDB,
                      "%s: cannot switch to WAL mode (journal_mode is '%s')",
                      s->path, mode);
    }
    if (rc == 0 && !readonly)
        rc = st_one_off(s, sync_full ? "PRAGMA synchronous = FULL"
                                  : "PRAGMA synchronous = NORMAL",
                     s->path, NULL, NULL, 0, err, errlen);
    if (rc == 0) {
        int64_t fk = 0;
        rc = st_one_off(s, "PRAGMA foreign_keys = ON", s->path, NULL, NULL, 0, err,
                     errlen);
        if (rc == 0)
            rc = st_one_off(s, "PRAGMA foreign_keys", s->path, &fk, NULL, 0, err,
                         errlen);
        if (rc == 0 && fk != 1)
            rc = st_fail(err, errlen, AMFI_STORE_EDB,
                      "%s: SQLite built without foreign keys", s->path);
    }
    if (rc == 0 && !readonly && version < AMFI_STORE_SCHEMA_VERSION)
        rc = migrate(s, err, errlen);
    for (int k = 0; rc == 0 && k < N_STMT; k++) {
        char ins[1024];
        const char *sql = stmt_sql[k];
        if (stmt_table[k]) {
            if (st_insert_sql(amfi_store_tabledef_find(stmt_table[k]), ins, sizeof ins) != 0) {
                rc = st_fail(err, errlen, AMFI_EINVAL, "%s: insert too long", stmt_table[k]);
                break;
            }
            sql = ins;
        }
        if (stmt_read[k].table) {
            char list[768];
            if (st_select_list(amfi_store_tabledef_find(stmt_read[k].table), list, sizeof list) != 0
                || snprintf(ins, sizeof ins, "SELECT id, %s FROM %s %s", list, stmt_read[k].table,
                            stmt_read[k].tail) >= (int)sizeof ins) {
                rc = st_fail(err, errlen, AMFI_EINVAL, "%s: read too long", stmt_read[k].table);
                break;
            }
            sql = ins;
        }
        src = sqlite3_prepare_v3(s->db, sql, -1,
                                 SQLITE_PREPARE_PERSISTENT, &s->st[k], NULL);
        if (src != SQLITE_OK)
            rc = st_db_fail(s, src, s->path, err, errlen);
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
    return open_store(path, 0, 0, sync_full, out, err, errlen);
}

int amfi_store_open_foreign(const char *path, int sync_full, amfi_store **out, char *err,
                            size_t errlen)
{
    return open_store(path, 0, 1, sync_full, out, err, errlen);
}

int amfi_store_open_readonly(const char *path, amfi_store **out, char *err,
                             size_t errlen)
{
    return open_store(path, 1, 1, 0, out, err, errlen);
}

/* ---- a reader of rows (amfi-sync) ------------------------------------------ */

int amfi_store_open_reader(const char *path, int immutable_ok, amfi_store **out, int *version,
                           int *immutable, char *err, size_t errlen)
{
    char wal[4200];
    if (!out || !version || !immutable)
        return st_fail(err, errlen, AMFI_EINVAL, "store: output is NULL");
    *out = NULL;
    *immutable = 0;
    if (!path || !*path)
        return st_fail(err, errlen, AMFI_EINVAL, "store: empty path");
    snprintf(wal, sizeof wal, "%s-wal", path);
    for (int pass = 0; pass < 2; pass++) {
        char uri[3 * 4096 + 32];
        const char *name = path;
        if (pass == 1) {
            /* a file: URI with the path percent-encoded */
            size_t k = (size_t)snprintf(uri, sizeof uri, "file:");
            for (const unsigned char *p = (const unsigned char *)path; *p && k + 4 < sizeof uri;
                 p++) {
                if ((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9')
                    || strchr("/._-~", *p))
                    uri[k++] = (char)*p;
                else
                    k += (size_t)snprintf(uri + k, sizeof uri - k, "%%%02X", *p);
            }
            snprintf(uri + k, sizeof uri - k, "?immutable=1");
            name = uri;
        }
        amfi_store *s = calloc(1, sizeof *s);
        if (!s)
            return st_fail(err, errlen, AMFI_ENOMEM, "%s: out of memory", path);
        snprintf(s->path, sizeof s->path, "%s", path);
        s->readonly = 1;
        int src = sqlite3_open_v2(name, &s->db,
                                  SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX
                                      | (pass ? SQLITE_OPEN_URI : 0),
                                  NULL);
        if (src != SQLITE_OK) {
            int rc = st_fail(err, errlen, AMFI_STORE_EDB, "%s: cannot open the store read-only: %s",
                             path, s->db ? sqlite3_errmsg(s->db) : sqlite3_errstr(src));
            destroy(s, 0);
            return rc;
        }
        sqlite3_extended_result_codes(s->db, 1);
        sqlite3_busy_timeout(s->db, AMFI_STORE_BUSY_TIMEOUT_MS);
        if (harden(s, 2, err, errlen) != 0) {
            destroy(s, 0);
            return AMFI_STORE_ESCHEMA;
        }
        sqlite3_stmt *uv = NULL;
        int ok = sqlite3_prepare_v2(s->db, "PRAGMA user_version", -1, &uv, NULL) == SQLITE_OK
                 && sqlite3_step(uv) == SQLITE_ROW;
        if (ok)
            *version = sqlite3_column_int(uv, 0);
        sqlite3_finalize(uv);
        if (ok) {
            /* the one prepared statement it uses (a file without meta fails
             * its reads) */
            if (sqlite3_prepare_v3(s->db, stmt_sql[ST_META_GET], -1, 0, &s->st[ST_META_GET], NULL)
                != SQLITE_OK)
                s->st[ST_META_GET] = NULL;
            *immutable = pass;
            *out = s;
            return 0;
        }
        int code = sqlite3_errcode(s->db) & 0xff;
        if (pass == 0 && immutable_ok && (code == SQLITE_READONLY || code == SQLITE_CANTOPEN)
            && access(wal, F_OK) != 0 && errno == ENOENT) {
            destroy(s, 0);
            continue;
        }
        int rc = st_fail(err, errlen, code == SQLITE_NOTADB ? AMFI_STORE_ECORRUPT : AMFI_STORE_EDB,
                         "%s: cannot read the store: %s", path, sqlite3_errmsg(s->db));
        destroy(s, 0);
        return rc;
    }
    return st_fail(err, errlen, AMFI_STORE_EDB, "%s: cannot read the store", path);
}
