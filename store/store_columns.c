/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_columns.c: the store's columns, table by table (store_columns.h):
 * the one place that says a column's name, type, field in the row struct,
 * unit, range, NULL rule and the migration that added it. The checks, the
 * INSERTs of the tables written from a row struct (store_rows.c), the
 * values read for other programs, the fleet's column rules and
 * docs/schema.md's column table come from here. Static data; any thread.
 */
#include "store_columns.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "store_internal.h"

#define UT_MAX AMFI_STORE_MAX_UTIME
#define KG AMFI_STORE_MAX_KG

/* Column makers. O: the field's offset in the table's row struct (ROW). */
#define O(f) offsetof(ROW, f)
/* id INTEGER PRIMARY KEY, filled by SQLite */
#define ID(v, ship, m)                                                                          \
    {.name = "id", .sql_type = 'i', .null_rule = AMFI_NULL_DB, .ilo = 1, .ihi = INT64_MAX,      \
     .unit = "", .since = v, .shipped = ship, .meaning = m}
/* INTEGER in [lo, hi], NOT NULL, from an int64_t / int field */
#define I64(n, f, lo_, hi_, u, v, ship, m)                                                      \
    {.name = n, .sql_type = 'i', .ctype = AMFI_C_I64, .off = O(f), .ilo = lo_, .ihi = hi_,      \
     .unit = u, .since = v, .shipped = ship, .meaning = m}
#define INT(n, f, lo_, hi_, u, v, ship, m)                                                      \
    {.name = n, .sql_type = 'i', .ctype = AMFI_C_INT, .off = O(f), .ilo = lo_, .ihi = hi_,      \
     .unit = u, .since = v, .shipped = ship, .meaning = m}
#define UTIME(n, f, v, ship, m) I64(n, f, 0, UT_MAX, "µs", v, ship, m)
/* REAL in lo .. hi (open: bit 1 lo excluded, bit 2 hi excluded), NULL rule nr */
#define REAL(n, f, nr, op, lo_, hi_, u, v, ship, m)                                             \
    {.name = n, .sql_type = 'r', .ctype = AMFI_C_DOUBLE, .off = O(f), .null_rule = nr,          \
     .null_ok = nr != AMFI_NULL_NEVER, .open = op, .lo = lo_, .hi = hi_, .unit = u, .since = v, \
     .shipped = ship, .meaning = m}
/* TEXT, one of the words vals */
#define ENUM(n, f, w, v, ship, m)                                                               \
    {.name = n, .sql_type = 't', .ctype = AMFI_C_STR, .off = O(f), .text_kind = AMFI_TEXT_ENUM, \
     .words = w, .unit = "", .since = v, .shipped = ship, .meaning = m}
/* TEXT of min .. max bytes (max 0: any), NULL rule nr, checked as kind */
#define TEXT(n, f, nr, kind, mn, mx, v, ship, m)                                                \
    {.name = n, .sql_type = 't', .ctype = AMFI_C_STR, .off = O(f), .null_rule = nr,             \
     .null_ok = nr == AMFI_NULL_PTR, .text_kind = kind, .min_len = mn, .max_len = mx,           \
     .unit = "", .since = v, .shipped = ship, .meaning = m}
/* TEXT NOT NULL with a DEFAULT of SQLite's (a wall-clock time) */
#define STAMP(n, v, ship, m)                                                                    \
    {.name = n, .sql_type = 't', .null_rule = AMFI_NULL_DB, .unit = "UTC", .since = v,          \
     .shipped = ship, .meaning = m}
#define N(a) ((int)(sizeof(a) / sizeof(a)[0]))

/* The enumerations' words (st_statuses, st_states, st_levels, st_sources
 * in store_internal.h, and these). */
static const char *const scale_kinds[] = {"scale_shift", "known_truck", NULL};
static const char *const inputs[] = {"accel", "vehicle", "truth", "environment", NULL};

/* ---- passages (amfi_passage_row) ------------------------------------------ */
#define ROW amfi_passage_row
static const amfi_store_coldef passages[] = {
    ID(1, 1, "passage_id of the AMFI_PASSAGE message"),
    I64("vehicle_id", vehicle_id, INT64_MIN, INT64_MAX, "", 1, 1, "from the vehicle detector"),
    UTIME("utime", utime, 1, 1, "data time the first axle reaches x = 0"),
    INT("lane", lane, -32768, 32767, "", 1, 1, "lane"),
    REAL("speed_mps", speed_mps, AMFI_NULL_NAN, 0, 0, AMFI_STORE_MAX_SPEED_MPS, "m/s", 1, 1,
         "the speed weighed with; NULL unknown"),
    INT("n_axles", n_axles, 0, AMFI_MAX_AXLES, "", 1, 1, "rows in axles; 0 unknown"),
    REAL("gvw_kg", gvw_kg, AMFI_NULL_NAN, 0, -KG, KG, "kg", 1, 1, "inferred GVW; NULL not solved"),
    ENUM("status", status, st_statuses, 1, 1,
         "ok needs gvw_kg > 0, speed_mps > 0, n_axles >= 1"),
    {.name = "reason", .sql_type = 't', .ctype = AMFI_C_STR, .off = O(reason),
     .null_rule = AMFI_NULL_EMPTY, .text_kind = AMFI_TEXT_UTF8, .wmax = AMFI_STORE_REASON_MAX,
     .unit = "", .since = 1, .shipped = 1, .meaning = "why not ok; '' when ok"},
    REAL("lambda", lambda, AMFI_NULL_NAN, 1, 0, HUGE_VAL, "", 1, 1, "λ at the reference rate"),
    REAL("residual_rms", residual_rms, AMFI_NULL_NAN, 0, 0, HUGE_VAL, "", 1, 1,
         "fit residual RMS, m/s²"),
    TEXT("formulation", formulation, AMFI_NULL_PTR, AMFI_TEXT_UTF8, 1, 63, 1, 1,
         "solver output equation"),
    REAL("solve_ms", solve_ms, AMFI_NULL_NAN, 0, 0, HUGE_VAL, "ms", 1, 1, "solver wall time"),
    STAMP("stored_at", 1, 1, "wall clock when stored"),
    REAL("speed_given_mps", speed_given_mps, AMFI_NULL_NAN, 0, 0, AMFI_STORE_MAX_SPEED_MPS, "m/s",
         3, 3, "the detector's speed; NULL unknown"),
    INT("speed_estimated", speed_estimated, 0, 1, "", 3, 3, "1: speed_mps was estimated"),
    {.name = "n_vehicles", .sql_type = 'i', .ctype = AMFI_C_INT, .off = O(n_vehicles),
     .null_rule = AMFI_NULL_ZERO_AS, .zero_as = 1, .ilo = 1, .ihi = 64, .unit = "", .since = 4,
     .shipped = 4, .meaning = "vehicles of the event it was weighed in (1 alone; 0 given is 1)"},
    REAL("quality", quality, AMFI_NULL_ZERO, 0, 1, 1e9, "", 4, 4,
         "separability from the event's other vehicles; NULL unknown"),
    REAL("reference_gvw_kg", reference_gvw_kg, AMFI_NULL_ZERO, 0, AMFI_STORE_MIN_REF_KG,
         AMFI_STORE_MAX_REF_KG, "kg", 6, 5, "a calibration truck's pre-weighed GVW"),
    {.name = "deck_c", .sql_type = 'r', .ctype = AMFI_C_DOUBLE, .off = O(deck_c),
     .null_rule = AMFI_NULL_FLAG, .flag_off = O(has_deck_c), .null_ok = 1,
     .lo = AMFI_STORE_MIN_TEMP_C, .hi = AMFI_STORE_MAX_TEMP_C, .unit = "°C", .since = 6,
     .shipped = 5, .meaning = "deck temperature taken for it; NULL none"},
    REAL("f1_hz", f1_hz, AMFI_NULL_ZERO, 1, 0, 1000, "Hz", 7, 5,
         "first natural frequency of the free vibration after it"),
    {.name = "f1_comp_hz", .sql_type = 'r', .ctype = AMFI_C_DOUBLE, .off = O(f1_comp_hz),
     .null_rule = AMFI_NULL_ZERO, .null_ok = 1, .open = 1, .lo = 0, .hi = 1000, .with = "f1_hz",
     .unit = "Hz", .since = 7, .shipped = 5, .meaning = "f1 at the calibration temperature"},
    {.name = "f1_zeta", .sql_type = 'r', .ctype = AMFI_C_DOUBLE, .off = O(f1_zeta),
     .null_rule = AMFI_NULL_NAN, .null_ok = 1, .open = 2, .lo = 0, .hi = 1, .with = "f1_hz",
     .unit = "", .since = 7, .shipped = 5, .meaning = "its damping ratio"},
    {.name = "f1_r2", .sql_type = 'r', .ctype = AMFI_C_DOUBLE, .off = O(f1_r2),
     .null_rule = AMFI_NULL_NAN, .null_ok = 1, .lo = 0, .hi = 1, .with = "f1_hz", .unit = "",
     .since = 7, .shipped = 5, .meaning = "the fit's R²"},
    REAL("gvw_comp_kg", gvw_comp_kg, AMFI_NULL_ZERO, 1, 0, KG, "kg", 8, 5,
         "the weight the STD and mean rules were fed; NULL did not feed them"),
    TEXT("class", vclass, AMFI_NULL_PTR, AMFI_TEXT_UTF8, 1, 15, 10, 7,
         "vehicle class from axles and spacings (classes: scheme), 'unknown'; NULL before v10"),
    TEXT("axle_groups", axle_groups, AMFI_NULL_PTR, AMFI_TEXT_UTF8, 1, 31, 10, 7,
         "axles per group front to back, e.g. 1-1-3; NULL before v10"),
    {.name = "overload", .sql_type = 'i', .ctype = AMFI_C_INT, .off = O(overload),
     .null_rule = AMFI_NULL_FLAG, .flag_off = O(has_overload), .null_ok = 1, .ilo = 0, .ihi = 1,
     .unit = "", .since = 10, .shipped = 7,
     .meaning = "1: GVW or a group above its class's legal limit; NULL not solved"},
    REAL("fit_ratio", fit_ratio, AMFI_NULL_ZERO, 1, 0, 1000, "", 12, 9,
         "the model's RMS residual over the free vibration after the last axle / the "
         "signal's there; NULL not fitted"),
    TEXT("loads_refused", loads_refused, AMFI_NULL_PTR, AMFI_TEXT_UTF8, 1,
         AMFI_STORE_LOADS_REFUSED_MAX, 13, 10,
         "why the classification refused the loads (a single axle or a group below zero, or "
         "above 10 x any legal load): never an overload; NULL judged, not solved, or before "
         "v13"),
};
#undef ROW

/* ---- axles (written from amfi_passage_row's arrays, store_write.c) -------- */
#define ROW amfi_passage_row
static const amfi_store_coldef axles[] = {
    {.name = "passage_id", .sql_type = 'i', .null_rule = AMFI_NULL_DB, .ilo = 1,
     .ihi = INT64_MAX, .unit = "", .since = 1, .shipped = 1, .meaning = "passages.id"},
    {.name = "idx", .sql_type = 'i', .null_rule = AMFI_NULL_DB, .ilo = 1, .ihi = AMFI_MAX_AXLES,
     .unit = "", .since = 1, .shipped = 1, .meaning = "1 = front axle"},
    {.name = "spacing_m", .sql_type = 'r', .null_rule = AMFI_NULL_DB, .null_ok = 1, .open = 1,
     .lo = 0, .hi = AMFI_STORE_MAX_SPACING_M, .unit = "m", .since = 1, .shipped = 1,
     .meaning = "to axle idx - 1; NULL for idx 1"},
    {.name = "load_kg", .sql_type = 'r', .null_rule = AMFI_NULL_DB, .null_ok = 1, .lo = -KG,
     .hi = KG, .unit = "kg", .since = 1, .shipped = 1, .meaning = "inferred axle load"},
};
#undef ROW

/* ---- truth, truth_axles (simulation; amfi_store_add_truth's arguments) ---- */
static const amfi_store_coldef truth[] = {
    ID(1, 0, "truth row"),
    {.name = "vehicle_id", .sql_type = 'i', .null_rule = AMFI_NULL_DB, .ilo = INT64_MIN,
     .ihi = INT64_MAX, .unit = "", .since = 1, .meaning = "as passages.vehicle_id"},
    {.name = "utime", .sql_type = 'i', .null_rule = AMFI_NULL_DB, .ilo = 0, .ihi = UT_MAX,
     .unit = "µs", .since = 1, .meaning = "as passages.utime"},
    {.name = "gvw_kg", .sql_type = 'r', .null_rule = AMFI_NULL_DB, .open = 1, .lo = 0, .hi = KG,
     .unit = "kg", .since = 1, .meaning = "true GVW"},
    {.name = "n_axles", .sql_type = 'i', .null_rule = AMFI_NULL_DB, .ilo = 1,
     .ihi = AMFI_MAX_AXLES, .unit = "", .since = 1, .meaning = "rows in truth_axles"},
    {.name = "speed_true_mps", .sql_type = 'r', .null_rule = AMFI_NULL_DB, .null_ok = 1,
     .open = 1, .lo = 0, .hi = AMFI_STORE_MAX_SPEED_MPS, .unit = "m/s", .since = 1,
     .meaning = "NULL unknown"},
};
static const amfi_store_coldef truth_axles[] = {
    {.name = "truth_id", .sql_type = 'i', .null_rule = AMFI_NULL_DB, .ilo = 1, .ihi = INT64_MAX,
     .unit = "", .since = 1, .meaning = "truth.id"},
    {.name = "idx", .sql_type = 'i', .null_rule = AMFI_NULL_DB, .ilo = 1, .ihi = AMFI_MAX_AXLES,
     .unit = "", .since = 1, .meaning = "1 = front axle"},
    {.name = "load_kg", .sql_type = 'r', .null_rule = AMFI_NULL_DB, .open = 1, .lo = 0, .hi = KG,
     .unit = "kg", .since = 1, .meaning = "static axle load"},
    {.name = "mean_force_N", .sql_type = 'r', .null_rule = AMFI_NULL_DB, .null_ok = 1,
     .lo = -AMFI_STORE_MAX_FORCE_N, .hi = AMFI_STORE_MAX_FORCE_N, .unit = "N", .since = 1,
     .meaning = "mean contact force on the span"},
};

/* ---- indicators (amfi_indicator_row) -------------------------------------- */
#define ROW amfi_indicator_row
static const amfi_store_coldef indicators[] = {
    ID(1, 1, "indicator_id of the AMFI_INDICATOR message"),
    UTIME("utime", utime, 1, 1, "data time of the newest passage in the window"),
    INT("n", n, 0, INT32_MAX, "", 1, 1, "ok passages in the window"),
    REAL("mean_kg", mean_kg, AMFI_NULL_NAN, 0, -KG, KG, "kg", 1, 1, "window mean GVW"),
    REAL("std_kg", std_kg, AMFI_NULL_NAN, 0, 0, KG, "kg", 1, 1, "window STD of GVW"),
    REAL("baseline_mean_kg", baseline_mean_kg, AMFI_NULL_NAN, 1, 0, KG, "kg", 1, 1,
         "the baseline's mean"),
    REAL("baseline_std_kg", baseline_std_kg, AMFI_NULL_NAN, 1, 0, KG, "kg", 1, 1,
         "the baseline's STD"),
    REAL("std_ratio", std_ratio, AMFI_NULL_NAN, 0, 0, 1e6, "", 1, 1, "std_kg / baseline_std_kg"),
    REAL("p_value", p_value, AMFI_NULL_NAN, 0, 0, 1, "", 1, 1, "one-sided variance-ratio test"),
    ENUM("state", state, st_states, 1, 1, "the indicator's state"),
};
#undef ROW

/* ---- alerts (st_alert_row, amfi_store_add_alert's arguments) -------------- */
#define ROW st_alert_row
static const amfi_store_coldef alerts[] = {
    ID(1, 1, "alert_id of the AMFI_ALERT message"),
    UTIME("utime", utime, 1, 1, "data time"),
    ENUM("level", level, st_levels, 1, 1, "info or warning"),
    TEXT("kind", kind, AMFI_NULL_NEVER, AMFI_TEXT_TOKEN, 1, 31, 1, 1,
         "std_increase, mean_shift, ..."),
    {.name = "message", .sql_type = 't', .ctype = AMFI_C_STR, .off = O(message),
     .text_kind = AMFI_TEXT_UTF8, .wmin = 1, .wmax = AMFI_STORE_REASON_MAX, .unit = "",
     .since = 1, .shipped = 1, .meaning = "the alert's text"},
    {.name = "indicator_id", .sql_type = 'i', .ctype = AMFI_C_I64, .off = O(indicator_id),
     .null_rule = AMFI_NULL_OPTIONAL, .null_ok = 1, .ilo = INT64_MIN, .ihi = INT64_MAX,
     .unit = "", .since = 1, .shipped = 1, .meaning = "the indicator behind it; NULL none"},
    INT("raised", raised, 0, 1, "", 1, 1, "1 raised, 0 cleared"),
};
#undef ROW

/* ---- baseline (amfi_baseline; check_baseline in store_write.c) ------------ */
static const amfi_store_coldef baseline[] = {
    ID(1, 1, "the newest row is the baseline in force"),
    {.name = "utime_set", .sql_type = 'i', .null_rule = AMFI_NULL_DB, .ilo = 0, .ihi = UT_MAX,
     .unit = "µs", .since = 1, .shipped = 1, .meaning = "data time from which it applies"},
    {.name = "n", .sql_type = 'i', .null_rule = AMFI_NULL_DB, .ilo = 2, .ihi = INT32_MAX,
     .unit = "", .since = 1, .shipped = 1, .meaning = "ok passages behind it"},
    {.name = "mean_kg", .sql_type = 'r', .null_rule = AMFI_NULL_DB, .open = 1, .lo = 0, .hi = KG,
     .unit = "kg", .since = 1, .shipped = 1, .meaning = "healthy mean GVW"},
    {.name = "std_kg", .sql_type = 'r', .null_rule = AMFI_NULL_DB, .open = 1, .lo = 0, .hi = KG,
     .unit = "kg", .since = 1, .shipped = 1, .meaning = "healthy STD of GVW"},
    {.name = "source", .sql_type = 't', .null_rule = AMFI_NULL_DB, .text_kind = AMFI_TEXT_ENUM,
     .words = st_sources, .unit = "", .since = 1, .shipped = 1,
     .meaning = "auto (amfid) or manual (amfi-report)"},
    {.name = "note", .sql_type = 't', .null_rule = AMFI_NULL_DB, .max_len = 127, .unit = "",
     .since = 1, .shipped = 1, .meaning = "free text"},
    STAMP("set_at", 1, 1, "wall clock when set"),
};

/* ---- meta, runs ----------------------------------------------------------- */
static const amfi_store_coldef meta[] = {
    {.name = "key", .sql_type = 't', .null_rule = AMFI_NULL_DB, .min_len = 1,
     .max_len = AMFI_STORE_META_KEY_MAX, .unit = "", .since = 1,
     .meaning = "[A-Za-z0-9_.-] (site.id, amfid's state)"},
    {.name = "value", .sql_type = 't', .null_rule = AMFI_NULL_DB,
     .max_len = AMFI_STORE_META_VALUE_MAX, .unit = "", .since = 1, .meaning = "UTF-8 text"},
    STAMP("updated_at", 1, 0, "wall clock of the last change"),
};
static const amfi_store_coldef runs[] = {
    ID(2, 1, "one row per start of amfid"),
    STAMP("started_at", 2, 1, "wall clock"),
    {.name = "version", .sql_type = 't', .null_rule = AMFI_NULL_DB, .min_len = 1, .max_len = 63,
     .unit = "", .since = 2, .shipped = 1, .meaning = "amfid --version"},
    {.name = "config_path", .sql_type = 't', .null_rule = AMFI_NULL_DB, .min_len = 1,
     .max_len = 4096, .unit = "", .since = 2, .shipped = 1, .meaning = "the configuration read"},
};

/* ---- environment (amfi_environment_row) ----------------------------------- */
#define ROW amfi_environment_row
static const amfi_store_coldef environment[] = {
    ID(5, 5, "one reading"),
    UTIME("utime", utime, 5, 5, "data time of the reading"),
    REAL("deck_c", deck_c, AMFI_NULL_NEVER, 0, AMFI_STORE_MIN_TEMP_C, AMFI_STORE_MAX_TEMP_C, "°C",
         5, 5, "deck temperature"),
    REAL("air_c", air_c, AMFI_NULL_NEVER, 0, AMFI_STORE_MIN_TEMP_C, AMFI_STORE_MAX_TEMP_C, "°C", 5,
         5, "air temperature"),
    UTIME("received_utime", received_utime, 5, 5, "wall clock when amfid received it"),
};
#undef ROW

/* ---- scale_evals (amfi_scale_eval_row) ------------------------------------ */
#define ROW amfi_scale_eval_row
static const amfi_store_coldef scale_evals[] = {
    ID(6, 5, "one scale block or known-truck run"),
    UTIME("utime", utime, 6, 5, "data time of the block's newest passage / of the run"),
    ENUM("kind", kind, scale_kinds, 6, 5, "which indicator"),
    INT("n", n, 0, INT32_MAX, "", 6, 5, "vehicles in the block / runs so far"),
    REAL("value", value, AMFI_NULL_NAN, 1, 0, 100, "", 6, 5, "compensated scale / ratio"),
    REAL("raw", raw, AMFI_NULL_NAN, 1, 0, 100, "", 6, 5, "the same without compensation"),
    REAL("deck_c", deck_c, AMFI_NULL_NAN, 0, AMFI_STORE_MIN_TEMP_C, AMFI_STORE_MAX_TEMP_C, "°C", 6,
         5, "block's mean / run's deck temperature"),
    REAL("z", z, AMFI_NULL_NAN, 0, -1e6, 1e6, "", 6, 5, "standardized increment"),
    REAL("cusum", cusum, AMFI_NULL_NAN, 0, 0, 1e6, "", 6, 5, "CUSUM statistic after it"),
    REAL("h", h, AMFI_NULL_NAN, 0, 0, 1e6, "", 6, 5, "its threshold"),
    ENUM("state", state, st_states, 6, 5, "the indicator's state"),
};
#undef ROW

/* ---- refusals (amfi_refusal_row) ------------------------------------------ */
#define ROW amfi_refusal_row
static const amfi_store_coldef refusals[] = {
    ID(9, 0, "one period, input channel and reason"),
    UTIME("period_start", period_start, 9, 0, "wall clock: the period's start"),
    UTIME("period_end", period_end, 9, 0, "wall clock: when it was summarised (>= period_start)"),
    TEXT("channel", channel, AMFI_NULL_NEVER, AMFI_TEXT_BYTES, 1, 63, 9, 0, "the bus channel"),
    ENUM("input", input, inputs, 9, 0, "which input"),
    TEXT("reason", reason, AMFI_NULL_NEVER, AMFI_TEXT_BYTES, 1, 63, 9, 0, "amfid's reason name"),
    I64("count", count, 1, INT64_MAX, "", 9, 0, "refused in the period for this reason"),
    {.name = "example", .sql_type = 't', .ctype = AMFI_C_STR, .off = O(example),
     .text_kind = AMFI_TEXT_BYTES, .max_len = 512, .cut = 512, .unit = "", .since = 9,
     .meaning = "the first one's log line (cut at 512 characters)"},
};
#undef ROW

/* ---- raw_windows, passage_raw (written and read by store_raw.c) ----------- */
#define RAWV AMFI_STORE_RAW_VERSION
static const char *const raw_encodings[] = {"f64-xor-shuffle-zlib", "f32-xor-shuffle-zlib",
                                            NULL};
static const amfi_store_coldef raw_windows[] = {
    ID(RAWV, 0, "one window weighed: a vehicle, or an event of several weighed together"),
    {.name = "utime", .sql_type = 'i', .null_rule = AMFI_NULL_DB, .ilo = 0, .ihi = UT_MAX,
     .unit = "µs", .since = RAWV, .meaning = "data time of the first vehicle's entry (t = 0)"},
    {.name = "rate_hz", .sql_type = 'r', .null_rule = AMFI_NULL_DB, .open = 1, .lo = 0,
     .hi = 100000, .unit = "Hz", .since = RAWV, .meaning = "sample rate"},
    {.name = "t_first_s", .sql_type = 'r', .null_rule = AMFI_NULL_DB, .lo = -3600, .hi = 3600,
     .unit = "s", .since = RAWV, .meaning = "time of the first sample after utime"},
    {.name = "n_samples", .sql_type = 'i', .null_rule = AMFI_NULL_DB, .ilo = 1, .ihi = INT32_MAX,
     .unit = "", .since = RAWV, .meaning = "samples per sensor"},
    {.name = "sensors", .sql_type = 't', .null_rule = AMFI_NULL_DB, .min_len = 3,
     .max_len = 1024, .unit = "", .since = RAWV,
     .meaning = "ID@AT_M of each sensor, comma-separated, in the samples' order"},
    {.name = "vehicles", .sql_type = 't', .null_rule = AMFI_NULL_DB, .min_len = 7,
     .max_len = 32768, .unit = "", .since = RAWV,
     .meaning = "the detector records weighed, ';'-separated (docs/schema.md)"},
    {.name = "solve", .sql_type = 't', .null_rule = AMFI_NULL_DB, .min_len = 1, .max_len = 1024,
     .unit = "", .since = RAWV, .meaning = "the solver's λ policy and speed settings at release"},
    {.name = "encoding", .sql_type = 't', .null_rule = AMFI_NULL_DB,
     .text_kind = AMFI_TEXT_ENUM, .words = raw_encodings, .unit = "", .since = RAWV,
     .meaning = "how samples is encoded: float64 exact, or rounded to float32"},
    {.name = "bytes", .sql_type = 'i', .null_rule = AMFI_NULL_DB, .ilo = 1, .ihi = INT64_MAX,
     .unit = "B", .since = RAWV, .meaning = "length(samples)"},
    {.name = "samples", .sql_type = 'b', .null_rule = AMFI_NULL_DB, .min_len = 1, .unit = "",
     .since = RAWV, .meaning = "every sensor's samples, compressed (encoding)"},
};
static const amfi_store_coldef passage_raw[] = {
    {.name = "passage_id", .sql_type = 'i', .null_rule = AMFI_NULL_DB, .ilo = 1,
     .ihi = INT64_MAX, .unit = "", .since = RAWV, .meaning = "passages.id"},
    {.name = "window_id", .sql_type = 'i', .null_rule = AMFI_NULL_DB, .ilo = 1,
     .ihi = INT64_MAX, .unit = "", .since = RAWV, .meaning = "raw_windows.id"},
    {.name = "vehicle", .sql_type = 'i', .null_rule = AMFI_NULL_DB, .ilo = 0, .ihi = 63,
     .unit = "", .since = RAWV, .meaning = "its place in the window's vehicles (0: the first)"},
};
#undef RAWV

const amfi_store_tabledef amfi_store_tabledefs[] = {
    {"passages", passages, N(passages), "id", sizeof(amfi_passage_row)},
    {"axles", axles, N(axles), "passage_id", 0},
    {"truth", truth, N(truth), "id", 0},
    {"truth_axles", truth_axles, N(truth_axles), "truth_id", 0},
    {"indicators", indicators, N(indicators), "id", sizeof(amfi_indicator_row)},
    {"alerts", alerts, N(alerts), "id", sizeof(st_alert_row)},
    {"baseline", baseline, N(baseline), "id", 0},
    {"meta", meta, N(meta), NULL, 0},
    {"runs", runs, N(runs), "id", 0},
    {"environment", environment, N(environment), "id", sizeof(amfi_environment_row)},
    {"scale_evals", scale_evals, N(scale_evals), "id", sizeof(amfi_scale_eval_row)},
    {"refusals", refusals, N(refusals), "id", sizeof(amfi_refusal_row)},
    {"raw_windows", raw_windows, N(raw_windows), "id", 0},
    {"passage_raw", passage_raw, N(passage_raw), "passage_id", 0},
};
const int amfi_store_n_tabledefs = N(amfi_store_tabledefs);

const amfi_store_tabledef *amfi_store_tabledef_find(const char *name)
{
    for (int k = 0; name && k < amfi_store_n_tabledefs; k++)
        if (strcmp(amfi_store_tabledefs[k].name, name) == 0)
            return &amfi_store_tabledefs[k];
    return NULL;
}

int amfi_store_coldef_index(const amfi_store_tabledef *t, const char *name)
{
    for (int k = 0; t && name && k < t->ncols; k++)
        if (strcmp(t->cols[k].name, name) == 0)
            return k;
    return -1;
}

/* ---- values --------------------------------------------------------------- */

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

const char *amfi_store_value_problem(const amfi_store_coldef *c, const amfi_store_value *v,
                                     char *msg, size_t msglen)
{
    static const char *const names[] = {"?", "an integer", "a real", "text", "a blob", "NULL"};
    const char *want = c->sql_type == 'i'   ? "an integer"
                       : c->sql_type == 'r' ? "a number"
                       : c->sql_type == 'b' ? "a blob"
                                            : "text";
    int type = v->type == 'i' ? 1 : v->type == 'r' ? 2 : v->type == 't' ? 3 : v->type == 'b' ? 4
                                                                                          : 5;
    if (type == 5) {
        if (c->null_ok) return NULL;
        snprintf(msg, msglen, "NULL, but it must be %s", want);
        return msg;
    }
    int ok_type = c->sql_type == 'i'   ? type == 1
                  : c->sql_type == 'r' ? type == 1 || type == 2
                  : c->sql_type == 'b' ? type == 4
                                       : type == 3;
    if (!ok_type) {
        snprintf(msg, msglen, "%s, but it must be %s", names[type], want);
        return msg;
    }
    if (c->sql_type == 'i') {
        if (v->i < c->ilo || v->i > c->ihi) {
            snprintf(msg, msglen, "%lld is not in [%lld, %lld]", (long long)v->i,
                     (long long)c->ilo, (long long)c->ihi);
            return msg;
        }
        return NULL;
    }
    if (c->sql_type == 'r') {
        double x = type == 1 ? (double)v->i : v->r;
        if (!isfinite(x) || ((c->open & 1) ? !(x > c->lo) : !(x >= c->lo))
            || ((c->open & 2) ? !(x < c->hi) : !(x <= c->hi))) {
            snprintf(msg, msglen, "%.17g is not in %c%.17g, %.17g%c", x, (c->open & 1) ? '(' : '[',
                     c->lo, c->hi, (c->open & 2) ? ')' : ']');
            return msg;
        }
        return NULL;
    }
    int len = v->len;
    if (len < c->min_len || (c->max_len && len > c->max_len)) {
        snprintf(msg, msglen, "%s of %d bytes, not %d..%d", type == 4 ? "a blob" : "text", len,
                 c->min_len, c->max_len ? c->max_len : INT32_MAX);
        return msg;
    }
    if (type == 4) /* a blob: only its length is the column table's */
        return NULL;
    if (!utf8_ok((const unsigned char *)v->text, len)) {
        snprintf(msg, msglen, "text that is not valid UTF-8 (or holds a NUL byte)");
        return msg;
    }
    if (c->words) {
        char all[160];
        for (const char *const *w = c->words; *w; w++)
            if (strlen(*w) == (size_t)len && memcmp(*w, v->text, (size_t)len) == 0) return NULL;
        snprintf(msg, msglen, "'%.40s' is not one of %s", v->text,
                 amfi_store_coldef_words(c, "|", all, sizeof all));
        /* the value shown may hold control characters: made '?' */
        for (char *p = msg; *p; p++)
            if ((unsigned char)*p < 0x20) *p = '?';
        return msg;
    }
    return NULL;
}

const char *amfi_store_coldef_words(const amfi_store_coldef *c, const char *sep, char *buf,
                                    size_t len)
{
    size_t k = 0;
    if (len)
        buf[0] = '\0';
    for (const char *const *w = c->words; w && *w && k < len; w++)
        k += (size_t)snprintf(buf + k, len - k, "%s%s", w == c->words ? "" : sep, *w);
    return buf;
}

const char *amfi_store_value_text(const amfi_store_value *v, char *buf, size_t len)
{
    switch (v->type) {
    case 'i': snprintf(buf, len, "%lld", (long long)v->i); return buf;
    case 'r': snprintf(buf, len, "%.17g", v->r); return buf;
    case 't':
    case 'b': return v->text;
    default: return NULL;
    }
}

/* ---- docs/schema.md -------------------------------------------------------- */

static void range_text(const amfi_store_coldef *c, char *buf, size_t len)
{
    buf[0] = '\0';
    if (c->sql_type == 'i') {
        if (c->ilo == INT64_MIN && c->ihi == INT64_MAX)
            snprintf(buf, len, "any");
        else if (c->ihi == INT64_MAX || c->ihi == INT32_MAX)
            snprintf(buf, len, ">= %lld", (long long)c->ilo);
        else
            snprintf(buf, len, "%lld .. %lld", (long long)c->ilo, (long long)c->ihi);
    } else if (c->sql_type == 'r') {
        if (isinf(c->hi))
            snprintf(buf, len, "%s %g", (c->open & 1) ? ">" : ">=", c->lo);
        else
            snprintf(buf, len, "%c%g, %g%c", (c->open & 1) ? '(' : '[', c->lo, c->hi,
                     (c->open & 2) ? ')' : ']');
    } else if (c->words) {
        amfi_store_coldef_words(c, "/", buf, len);
    } else if (c->max_len || c->min_len || c->wmax) {
        int mn = c->wmax ? c->wmin : c->min_len, mx = c->wmax ? c->wmax : c->max_len;
        if (mx)
            snprintf(buf, len, "%d .. %d bytes", mn, mx);
        else
            snprintf(buf, len, ">= %d bytes", mn);
    }
}

static const char *null_text(const amfi_store_coldef *c)
{
    switch (c->null_rule) {
    case AMFI_NULL_NAN: return "NaN is NULL";
    case AMFI_NULL_ZERO: return "NaN or 0 is NULL";
    case AMFI_NULL_PTR: return "NULL pointer is NULL";
    case AMFI_NULL_EMPTY: return "NOT NULL; NULL pointer is ''";
    case AMFI_NULL_FLAG: return "NULL unless its flag is set";
    case AMFI_NULL_ZERO_AS: return "NOT NULL; 0 given is stored as 1";
    case AMFI_NULL_OPTIONAL: return "<= 0 is NULL";
    case AMFI_NULL_DB: return c->null_ok ? "NULL allowed" : "NOT NULL";
    default: return "NOT NULL";
    }
}

int amfi_store_columns_markdown(FILE *f)
{
    char rtext[96];
    for (int k = 0; k < amfi_store_n_tabledefs; k++) {
        const amfi_store_tabledef *t = &amfi_store_tabledefs[k];
        fprintf(f, "%s#### %s\n\n", k ? "\n" : "", t->name);
        fprintf(f, "| column | type | unit | range | NULL | since | shipped | meaning |\n");
        fprintf(f, "|---|---|---|---|---|---|---|---|\n");
        for (int j = 0; j < t->ncols; j++) {
            const amfi_store_coldef *c = &t->cols[j];
            range_text(c, rtext, sizeof rtext);
            char with[64] = "";
            if (c->with) snprintf(with, sizeof with, "; NULL when %s is", c->with);
            char ship[8] = "-";
            if (c->shipped) snprintf(ship, sizeof ship, "v%d", c->shipped);
            fprintf(f, "| %s | %s | %s | %s | %s%s | %d | %s | %s |\n", c->name,
                    c->sql_type == 'i'   ? "INTEGER"
                    : c->sql_type == 'r' ? "REAL"
                    : c->sql_type == 'b' ? "BLOB"
                                         : "TEXT",
                    c->unit && c->unit[0] ? c->unit : "", rtext, null_text(c), with, c->since,
                    ship, c->meaning ? c->meaning : "");
        }
    }
    return ferror(f) ? -1 : 0;
}
