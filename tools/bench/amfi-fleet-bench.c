/* SPDX-License-Identifier: GPL-3.0-or-later */
/* amfi-fleet-bench: the fleet at scale (issue 15, docs/fleet.md). Builds N
 * simulated site stores of D days at V vehicles a day each (real amfi store
 * schema: passages with two axles, an indicator per window, a few alerts),
 * ships every store with the real amfi-sync --once (J at a time) into the
 * central PostgreSQL given by --pg, and times the fleet views. Prints the
 * figures; fails only when a step fails or the central counts differ from
 * the stores'. Every tenth site ends with an open alert. Single-threaded;
 * J child processes for generation and sync. */
#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <libpq-fe.h>

#include "amfi_cli.h"
#include "store.h"
#include "amfi_time.h"

#define WINDOW 500 /* ok passages behind one indicator row */

static struct {
    const char *pg, *sync, *dir;
    int sites, days, per_day, jobs, keep;
    unsigned long seed;
    long long start_s; /* first day, s since 1970 UTC */
} opt = {NULL, NULL, NULL, 50, 365, 2000, 2, 0, 1, 1735689600LL /* 2025-01-01 */};

static void site_paths(int k, char *id, size_t idlen, char *path, size_t plen)
{
    snprintf(id, idlen, "bench-%03d", k);
    snprintf(path, plen, "%s/%s.db", opt.dir, id);
}

/* Column values for the store's inserter (store.h, rows as column values). */
static amfi_store_value vi(int64_t x) { return (amfi_store_value){.type = AMFI_SQL_INTEGER, .i = x}; }
static amfi_store_value vr(double x) { return (amfi_store_value){.type = AMFI_SQL_REAL, .r = x}; }
static amfi_store_value vt(const char *t) { return (amfi_store_value){.type = AMFI_SQL_TEXT, .text = t}; }
static const amfi_store_value vnull = {0};

/* One site's store: the schema from amfi_store_open (so it is the real one,
 * with the site id in meta as amfid writes it), the rows by the store's
 * inserts by column value in large transactions (amfid's one transaction
 * per passage would take the bench hours). GVW: a loaded/empty mixture of
 * two-axle vehicles; 2 % of the passages 'multiple' (no weight). */
static int make_store(int k)
{
    static const char *const pcols[] = {"id", "vehicle_id", "utime", "lane", "speed_mps",
                                        "n_axles", "gvw_kg", "status", "reason", "lambda",
                                        "residual_rms", "formulation", "solve_ms"};
    static const char *const acols[] = {"passage_id", "idx", "spacing_m", "load_kg"};
    static const char *const icols[] = {"id", "utime", "n", "mean_kg", "std_kg",
                                        "baseline_mean_kg", "baseline_std_kg", "std_ratio",
                                        "p_value", "state"};
    static const char *const lcols[] = {"utime", "level", "kind", "message", "indicator_id",
                                        "raised"};
    char id[32], path[4096], err[512];
    site_paths(k, id, sizeof id, path, sizeof path);
    unlink(path);
    amfi_store *s = NULL;
    amfi_store_inserter *ps = NULL, *ax = NULL, *ind = NULL, *al = NULL;
    gsl_rng *r = NULL;
    int rc = -1;
    if (amfi_store_open(path, 0, &s, err, sizeof err) != 0
        || amfi_store_meta_set(s, "site.id", id, err, sizeof err) != 0
        || amfi_store_inserter_open(s, "passages", pcols, 13, &ps, err, sizeof err) != 0
        || amfi_store_inserter_open(s, "axles", acols, 4, &ax, err, sizeof err) != 0
        || amfi_store_inserter_open(s, "indicators", icols, 10, &ind, err, sizeof err) != 0
        || amfi_store_inserter_open(s, "alerts", lcols, 6, &al, err, sizeof err) != 0
        || amfi_store_transaction(s, AMFI_STORE_TX_WRITE, err, sizeof err) != 0)
        goto fail;
    r = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(r, opt.seed * 1000003UL + (unsigned long)k);
    int64_t pid = 0;
    int nwin = 0, nind = 0;
    double sum = 0, sum2 = 0;
    for (int d = 0; d < opt.days; d++) {
        double t = 0;
        for (int v = 0; v < opt.per_day; v++) {
            t += gsl_ran_exponential(r, 86400.0 / opt.per_day);
            if (t >= 86400) t = 86399.999;
            int64_t ut = (int64_t)((double)(opt.start_s + 86400LL * d) * 1e6 + t * 1e6);
            int multiple = gsl_rng_uniform(r) < 0.02;
            int loaded = gsl_rng_uniform(r) < 0.45;
            double gvw = loaded ? 30000 + gsl_ran_gaussian(r, 4000) : 12000 + gsl_ran_gaussian(r, 2000);
            if (gvw < 3000) gvw = 3000;
            double front = gvw * (0.35 + 0.05 * gsl_rng_uniform(r));
            double sp = 3.5 + 2.5 * gsl_rng_uniform(r);
            pid++;
            double speed = 25 + gsl_ran_gaussian(r, 2);
            amfi_store_value pv[13] = {vi(pid), vi(pid), vi(ut), vi(1 + (int)(pid % 2)), vr(speed),
                                       vi(2), vnull, vt("multiple"),
                                       vt("another vehicle on the span"), vnull, vnull,
                                       vt("acceleration"), vnull};
            if (!multiple) {
                pv[6] = vr(gvw);
                pv[7] = vt("ok");
                pv[8] = vt("");
                pv[9] = vr(1e-3);
                pv[10] = vr(0.01 + 0.002 * gsl_rng_uniform(r));
                pv[12] = vr(5 + gsl_rng_uniform(r));
            }
            if (amfi_store_insert_values(ps, pv, err, sizeof err) != 0) goto fail;
            for (int a = 1; a <= 2; a++) {
                amfi_store_value av[4] = {vi(pid), vi(a), a == 1 ? vnull : vr(sp),
                                          multiple ? vnull : vr(a == 1 ? front : gvw - front)};
                if (amfi_store_insert_values(ax, av, err, sizeof err) != 0) goto fail;
            }
            if (!multiple) {
                sum += gvw;
                sum2 += gvw * gvw;
                if (++nwin == WINDOW) {
                    double mean = sum / nwin, sd = sqrt((sum2 - nwin * mean * mean) / (nwin - 1));
                    nind++;
                    amfi_store_value iv[10] = {vi(nind), vi(ut), vi(nwin), vr(mean), vr(sd),
                                               vr(21000), vr(9000), vr(sd / 9000), vr(0.5),
                                               vt(nind <= 4 ? "baseline" : "normal")};
                    if (amfi_store_insert_values(ind, iv, err, sizeof err) != 0) goto fail;
                    /* a raised and cleared alert about every 200 windows */
                    if (nind % 200 == 100 || nind % 200 == 101) {
                        amfi_store_value lv[6] = {vi(ut), vt("warning"), vt("std_increase"),
                                                  vt("bench alert"), vi(nind),
                                                  vi(nind % 200 == 100)};
                        if (amfi_store_insert_values(al, lv, err, sizeof err) != 0) goto fail;
                    }
                    nwin = 0;
                    sum = sum2 = 0;
                }
            }
            if (pid % 100000 == 0
                && (amfi_store_transaction(s, AMFI_STORE_TX_COMMIT, err, sizeof err) != 0
                    || amfi_store_transaction(s, AMFI_STORE_TX_WRITE, err, sizeof err) != 0))
                goto fail;
        }
    }
    /* every tenth site ends with an alert still raised */
    if (k % 10 == 0) {
        amfi_store_value lv[6] = {vi((int64_t)(opt.start_s + 86400LL * opt.days) * 1000000 - 1),
                                  vt("warning"), vt("std_increase"), vt("bench alert"), vnull,
                                  vi(1)};
        if (amfi_store_insert_values(al, lv, err, sizeof err) != 0) goto fail;
    }
    if (amfi_store_transaction(s, AMFI_STORE_TX_COMMIT, err, sizeof err) != 0) goto fail;
    rc = 0;
    goto out;
fail:
    fprintf(stderr, "amfi-fleet-bench: %s: %s\n", path, err);
out:
    amfi_store_inserter_close(ps);
    amfi_store_inserter_close(ax);
    amfi_store_inserter_close(ind);
    amfi_store_inserter_close(al);
    amfi_store_close(s);
    gsl_rng_free(r);
    return rc;
}

/* Runs job(k) for k in 0..n-1, at most opt.jobs child processes at a time.
 * Returns the number of failed jobs. */
static int run_parallel(int n, int (*job)(int))
{
    int running = 0, failed = 0, next = 0;
    while (next < n || running > 0) {
        if (next < n && running < opt.jobs) {
            pid_t p = fork();
            if (p == 0) _exit(job(next) == 0 ? 0 : 1);
            if (p < 0) { perror("amfi-fleet-bench: fork"); return n; }
            next++;
            running++;
            continue;
        }
        int st;
        if (wait(&st) > 0) {
            running--;
            if (!WIFEXITED(st) || WEXITSTATUS(st) != 0) failed++;
        }
    }
    return failed;
}

static int sync_site(int k)
{
    char id[32], path[4096];
    site_paths(k, id, sizeof id, path, sizeof path);
    execl(opt.sync, opt.sync, "--db", path, "--pg", opt.pg, "--once", "--quiet", (char *)NULL);
    fprintf(stderr, "amfi-fleet-bench: %s: %s\n", opt.sync, strerror(errno));
    return -1;
}

static PGresult *q(PGconn *pg, const char *sql, int nparams, const char *const *params)
{
    PGresult *res = PQexecParams(pg, sql, nparams, NULL, params, NULL, NULL, 0);
    ExecStatusType st = PQresultStatus(res);
    if (st != PGRES_TUPLES_OK && st != PGRES_COMMAND_OK) {
        fprintf(stderr, "amfi-fleet-bench: %s: %s", sql, PQerrorMessage(pg));
        PQclear(res);
        return NULL;
    }
    return res;
}

/* Times a query: the first run (cold for this session's plan) and the best
 * of three more; prints rows and both times. */
static int time_query(PGconn *pg, const char *what, const char *sql, int nparams,
                      const char *const *params)
{
    double first = 0, best = 1e9;
    int rows = 0;
    for (int i = 0; i < 4; i++) {
        double t0 = amfi_mono_s();
        PGresult *res = q(pg, sql, nparams, params);
        double dt = amfi_mono_s() - t0;
        if (!res) return -1;
        rows = PQntuples(res);
        PQclear(res);
        if (i == 0) first = dt; else if (dt < best) best = dt;
    }
    printf("  %-44s %7d rows  first %8.1f ms  best %8.1f ms\n", what, rows, 1e3 * first, 1e3 * best);
    return 0;
}

static long long count_central(PGconn *pg, const char *sql)
{
    PGresult *res = q(pg, sql, 0, NULL);
    long long n = res && PQntuples(res) == 1 ? atoll(PQgetvalue(res, 0, 0)) : -1;
    PQclear(res);
    return n;
}

static void usage(FILE *f)
{
    fputs("usage: amfi-fleet-bench --pg CONNINFO --sync AMFI_SYNC --dir DIR [--sites N]\n"
          "         [--days D] [--per-day V] [--jobs J] [--seed S] [--keep]\n"
          "Builds N site stores (D days x V two-axle passages each) in DIR, ships them\n"
          "with AMFI_SYNC --once (J at a time) into the central database (its schema is\n"
          "created if absent) and times the fleet views. Defaults: 50 sites, 365 days,\n"
          "2000 a day, 2 jobs. --keep: reuse the stores already in DIR.\n", f);
}

int main(int argc, char **argv)
{
    static const struct option opts[] = {
        {"pg", required_argument, NULL, 'p'},   {"sync", required_argument, NULL, 'y'},
        {"dir", required_argument, NULL, 'd'},  {"sites", required_argument, NULL, 'n'},
        {"days", required_argument, NULL, 'D'}, {"per-day", required_argument, NULL, 'v'},
        {"jobs", required_argument, NULL, 'j'}, {"seed", required_argument, NULL, 's'},
        {"keep", no_argument, NULL, 'k'},       AMFI_CLI_END};
    amfi_cli c;
    amfi_cli_init(&c, "amfi-fleet-bench", argc, argv, opts, usage);
    for (int k; (k = amfi_cli_next(&c)) != -1;) {
        switch (k) {
        case 'p': opt.pg = optarg; break;
        case 'y': opt.sync = optarg; break;
        case 'd': opt.dir = optarg; break;
        case 'n': opt.sites = (int)amfi_cli_integer(&c, optarg, 1, 999); break;
        case 'D': opt.days = (int)amfi_cli_integer(&c, optarg, 1, 3660); break;
        case 'v': opt.per_day = (int)amfi_cli_integer(&c, optarg, 1, 200000); break;
        case 'j': opt.jobs = (int)amfi_cli_integer(&c, optarg, 1, 64); break;
        case 's': opt.seed = (unsigned long)amfi_cli_integer(&c, optarg, 0, 4294967295.0); break;
        case 'k': opt.keep = 1; break;
        default: usage(stderr); return AMFI_CLI_EXIT_USAGE;
        }
    }
    if (!opt.pg || !opt.sync || !opt.dir) {
        amfi_cli_error("amfi-fleet-bench", NULL, "--pg, --sync and --dir are required");
        usage(stderr);
        return AMFI_CLI_EXIT_USAGE;
    }
    long long total = (long long)opt.sites * opt.days * opt.per_day;
    printf("amfi-fleet-bench: %d sites x %d days x %d a day = %lld passages (2 axles each)\n",
           opt.sites, opt.days, opt.per_day, total);
    fflush(stdout);

    double t0 = amfi_mono_s();
    if (!opt.keep) {
        if (mkdir(opt.dir, 0755) != 0 && errno != EEXIST) {
            fprintf(stderr, "amfi-fleet-bench: %s: %s\n", opt.dir, strerror(errno));
            return 1;
        }
        if (run_parallel(opt.sites, make_store)) return 1;
        printf("stores built:   %8.1f s (%.0f passages/s, %d jobs)\n", amfi_mono_s() - t0,
               (double)total / (amfi_mono_s() - t0), opt.jobs);
        fflush(stdout);
    }

    PGconn *pg = PQconnectdb(opt.pg);
    if (PQstatus(pg) != CONNECTION_OK) {
        fprintf(stderr, "amfi-fleet-bench: server: %s", PQerrorMessage(pg));
        PQfinish(pg);
        return 1;
    }
    long long before = count_central(pg, "SELECT count(*) FROM passages WHERE site_id LIKE 'bench-%'");
    long long axles0 = count_central(pg, "SELECT count(*) FROM axles WHERE site_id LIKE 'bench-%'");
    double t1 = amfi_mono_s();
    if (run_parallel(opt.sites, sync_site)) { PQfinish(pg); return 1; }
    double dt = amfi_mono_s() - t1;
    long long after = count_central(pg, "SELECT count(*) FROM passages WHERE site_id LIKE 'bench-%'");
    long long axles = count_central(pg, "SELECT count(*) FROM axles WHERE site_id LIKE 'bench-%'");
    printf("shipped:        %8.1f s: %lld passages (+%lld axles) = %.0f passages/s with axles\n", dt,
           after - before, axles - axles0, (double)(after - before) / dt);
    if (before < 0 || after < 0 || axles0 < 0 || axles < 0) { PQfinish(pg); return 1; }
    if (!opt.keep && after != total) {
        fprintf(stderr, "amfi-fleet-bench: central holds %lld bench passages, the stores %lld\n",
                after, total);
        PQfinish(pg);
        return 1;
    }
    PGresult *res = q(pg, "ANALYZE", 0, NULL);
    PQclear(res);
    res = q(pg, "SELECT pg_size_pretty(pg_database_size(current_database()))", 0, NULL);
    if (res) printf("database size:  %s\n", PQgetvalue(res, 0, 0));
    PQclear(res);
    char site[32], path[4096], from[32], to[32];
    site_paths(opt.sites / 2, site, sizeof site, path, sizeof path);
    snprintf(from, sizeof from, "%lld", opt.start_s * 1000000LL);
    snprintf(to, sizeof to, "%lld", (opt.start_s + 86400LL * opt.days) * 1000000LL);
    const char *p1[] = {site};
    const char *p3[] = {site, from, to};
    printf("view timings (site %s where one site is asked; first run, then best of three):\n", site);
    int bad = time_query(pg, "fleet_latest_state (every site)",
                         "SELECT * FROM fleet_latest_state", 0, NULL) ||
              time_query(pg, "fleet_open_alerts (every site)",
                         "SELECT * FROM fleet_open_alerts", 0, NULL) ||
              time_query(pg, "fleet_daily_trend, one site, all days",
                         "SELECT * FROM fleet_daily_trend WHERE site_id = $1 ORDER BY day", 1, p1) ||
              time_query(pg, "fleet_passages_daily, one site, all days",
                         "SELECT * FROM fleet_passages_daily WHERE site_id = $1", 1, p1) ||
              time_query(pg, "passages of one site in the period (count)",
                         "SELECT count(*) FROM passages WHERE site_id = $1"
                         " AND utime >= $2 AND utime < $3", 3, p3);
    PQfinish(pg);
    printf("total:          %8.1f s\n", amfi_mono_s() - t0);
    return bad ? 1 : 0;
}
