/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_level_rule.c: the debounced median level alert (indicators/
 * level_rule.h) behind amfid's model_mismatch and natfreq alerts: the
 * parameter checks, no evaluation before the window is full, the median
 * ignoring a minority of outliers, the raise debounce (raise_after
 * evaluations in a row, a broken streak starting again), one event per
 * state change, the hysteresis band where nothing happens, the clear
 * debounce, the refill and alert state after a restart, refused figures;
 * the two-sided strict mode behind the speed-drift alert (|median| > raise
 * raises, |median| < clear clears).
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "level_rule.h"

static amfi_level_params params(int w, double raise, double clear, int ra, int ca)
{
    amfi_level_params p = {1, w, raise, clear, ra, ca, 0, 0};
    return p;
}

static amfi_level_rule *make(int w, double raise, double clear, int ra, int ca)
{
    amfi_level_params p = params(w, raise, clear, ra, ca);
    amfi_level_rule *l = NULL;
    char err[256];
    assert_int_equal(0, amfi_level_rule_create(&p, "model_mismatch", "warning", "ratio", &l, err,
                                               sizeof err));
    assert_non_null(l);
    return l;
}

static void test_params(void **state)
{
    (void)state;
    const char *field = NULL;
    char err[256];
    amfi_level_params p = params(5, 0.1, 0.05, 3, 3);
    assert_int_equal(0, amfi_level_params_check(&p, &field, err, sizeof err));
    p.window = 0;
    assert_int_equal(AMFI_IND_EINVAL, amfi_level_params_check(&p, &field, err, sizeof err));
    assert_string_equal(field, "window");
    p = params(5, 0.1, 0.1, 3, 3); /* no hysteresis band */
    assert_int_equal(AMFI_IND_EINVAL, amfi_level_params_check(&p, &field, err, sizeof err));
    assert_string_equal(field, "clear");
    assert_non_null(strstr(err, "below the raise level"));
    p = params(5, NAN, 0.05, 3, 3);
    assert_int_equal(AMFI_IND_EINVAL, amfi_level_params_check(&p, &field, err, sizeof err));
    assert_string_equal(field, "raise");
    p = params(5, 0.1, 0.05, 0, 3);
    assert_int_equal(AMFI_IND_EINVAL, amfi_level_params_check(&p, &field, err, sizeof err));
    assert_string_equal(field, "raise_after");
    p = params(5, 0.1, 0.05, 3, 0);
    assert_int_equal(AMFI_IND_EINVAL, amfi_level_params_check(&p, &field, err, sizeof err));
    assert_string_equal(field, "clear_after");
    p = params(5, 0.1, 0.05, 3, 3);
    p.enabled = 2;
    assert_int_equal(AMFI_IND_EINVAL, amfi_level_params_check(&p, &field, err, sizeof err));
    assert_string_equal(field, "enabled");
    amfi_level_rule *l = NULL;
    p.enabled = 1;
    p.window = -1;
    assert_int_equal(AMFI_IND_EINVAL,
                     amfi_level_rule_create(&p, "k", "warning", "x", &l, err, sizeof err));
    assert_null(l);
}

/* The text form amfid records in the store (meta alerts.model_fit) and
 * the reports read back: exact round trip, every refusal named. */
static void test_params_text(void **state)
{
    (void)state;
    char buf[256], err[256];
    amfi_level_params p = params(25, 0.1, 0.05, 10, 25), q;
    assert_int_equal(0, amfi_level_params_format(&p, buf, sizeof buf));
    assert_string_equal(buf, "enabled=1 window=25 raise=0.10000000000000001 "
                             "clear=0.050000000000000003 raise_after=10 clear_after=25");
    memset(&q, 0, sizeof q);
    assert_int_equal(0, amfi_level_params_parse(buf, &q, err, sizeof err));
    assert_int_equal(q.enabled, 1);
    assert_int_equal(q.window, 25);
    assert_true(q.raise == 0.1 && q.clear == 0.05);
    assert_int_equal(q.raise_after, 10);
    assert_int_equal(q.clear_after, 25);
    assert_int_equal(AMFI_IND_EINVAL, amfi_level_params_format(&p, buf, 20));
    assert_string_equal(buf, "");
    static const struct {
        const char *text, *says;
    } bad[] = {
        {"enabled=1 window=25 raise=0.1 clear=0.05 raise_after=10", "clear_after missing"},
        {"enabled=1 window=25 raise=x clear=0.05 raise_after=10 clear_after=25",
         "raise: not a number"},
        {"enabled=1 window=2.5 raise=0.1 clear=0.05 raise_after=10 clear_after=25",
         "window: trailing text"},
        {"enabled=1 window=25 window=25 raise=0.1 clear=0.05 raise_after=10 clear_after=25",
         "window given twice"},
        {"enabled=1 size=25 raise=0.1 clear=0.05 raise_after=10 clear_after=25",
         "unknown field at 'size=25"},
        {"enabled=1 window=25 raise=0.05 clear=0.1 raise_after=10 clear_after=25",
         "below the raise level"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        q = p;
        q.window = 7;
        err[0] = '\0';
        assert_int_equal(AMFI_IND_EINVAL, amfi_level_params_parse(bad[i].text, &q, err, sizeof err));
        if (!strstr(err, bad[i].says))
            fail_msg("'%s': '%s', want '%s'", bad[i].text, err, bad[i].says);
        assert_int_equal(q.window, 7); /* unchanged */
    }
}

static void test_raise_clear(void **state)
{
    (void)state;
    amfi_level_rule *l = make(5, 0.1, 0.05, 3, 2);
    amfi_level_eval ev;
    amfi_alert_event a;
    /* four figures: the window is not full */
    for (int i = 0; i < 4; i++)
        assert_int_equal(0, amfi_level_rule_push(l, 0.01, &ev, &a));
    assert_int_equal(AMFI_IND_EVAL, amfi_level_rule_push(l, 0.01, &ev, &a));
    assert_int_equal(5, ev.n);
    assert_true(fabs(ev.median - 0.01) < 1e-15);
    /* two outliers in five: the median stays low, no streak */
    assert_int_equal(AMFI_IND_EVAL, amfi_level_rule_push(l, 5.0, &ev, &a));
    assert_int_equal(AMFI_IND_EVAL, amfi_level_rule_push(l, 5.0, &ev, &a));
    assert_true(fabs(ev.median - 0.01) < 1e-15);
    assert_int_equal(0, ev.streak);
    /* the third high value makes the median high: streak 1, 2, then raised at 3 */
    assert_int_equal(AMFI_IND_EVAL, amfi_level_rule_push(l, 0.2, &ev, &a));
    assert_int_equal(1, ev.streak);
    assert_int_equal(AMFI_IND_EVAL, amfi_level_rule_push(l, 0.2, &ev, &a));
    assert_int_equal(2, ev.streak);
    assert_int_equal(AMFI_IND_EVAL | AMFI_IND_ALERT, amfi_level_rule_push(l, 0.2, &ev, &a));
    assert_int_equal(1, a.raised);
    assert_string_equal(a.kind, "model_mismatch");
    assert_string_equal(a.level, "warning");
    assert_non_null(strstr(a.message, "median ratio"));
    assert_true(amfi_level_rule_alerted(l));
    /* raised: nothing repeated while high, nor inside the band 0.05 .. 0.1 */
    for (int i = 0; i < 10; i++)
        assert_int_equal(AMFI_IND_EVAL, amfi_level_rule_push(l, 0.3, &ev, &a));
    for (int i = 0; i < 10; i++)
        assert_int_equal(AMFI_IND_EVAL, amfi_level_rule_push(l, 0.07, &ev, &a));
    assert_true(amfi_level_rule_alerted(l));
    /* low: the median low from the third value on; cleared at the second such evaluation */
    assert_int_equal(AMFI_IND_EVAL, amfi_level_rule_push(l, 0.01, &ev, &a));
    assert_int_equal(AMFI_IND_EVAL, amfi_level_rule_push(l, 0.01, &ev, &a));
    assert_int_equal(AMFI_IND_EVAL, amfi_level_rule_push(l, 0.01, &ev, &a));
    assert_int_equal(1, ev.streak);
    assert_int_equal(AMFI_IND_EVAL | AMFI_IND_ALERT, amfi_level_rule_push(l, 0.01, &ev, &a));
    assert_int_equal(0, a.raised);
    assert_false(amfi_level_rule_alerted(l));
    amfi_level_rule_destroy(l);
}

static void test_broken_streak(void **state)
{
    (void)state;
    amfi_level_rule *l = make(1, 1.0, 0.5, 3, 3);
    amfi_level_eval ev;
    amfi_alert_event a;
    /* high, high, low, high, high: never three in a row */
    const double x[] = {2, 2, 0.1, 2, 2, 0.1, 2, 2};
    for (size_t i = 0; i < sizeof x / sizeof *x; i++)
        assert_int_equal(AMFI_IND_EVAL, amfi_level_rule_push(l, x[i], &ev, &a));
    assert_false(amfi_level_rule_alerted(l));
    assert_int_equal(AMFI_IND_EVAL | AMFI_IND_ALERT, amfi_level_rule_push(l, 2, &ev, &a));
    amfi_level_rule_destroy(l);
}

static void test_restore_and_refusals(void **state)
{
    (void)state;
    amfi_level_rule *l = make(3, 0.1, 0.05, 1, 1);
    amfi_level_eval ev;
    amfi_alert_event a;
    const double old[] = {0.5, NAN, 0.5, 0.5};
    assert_int_equal(3, amfi_level_rule_prefill(l, old, 4));
    assert_int_equal(AMFI_IND_EINVAL, amfi_level_rule_prefill(l, NULL, 2));
    /* an alert open before the restart: not raised again */
    amfi_level_rule_set_alerted(l, 1);
    assert_int_equal(AMFI_IND_EVAL, amfi_level_rule_push(l, 0.5, &ev, &a));
    assert_int_equal(3, ev.n);
    assert_int_equal(AMFI_IND_EINVAL, amfi_level_rule_push(l, NAN, &ev, &a));
    assert_int_equal(AMFI_IND_EINVAL, amfi_level_rule_push(NULL, 0.1, &ev, &a));
    amfi_level_rule_destroy(l);
    /* off: nothing */
    amfi_level_params p = params(1, 0.1, 0.05, 1, 1);
    p.enabled = 0;
    char err[128];
    assert_int_equal(0, amfi_level_rule_create(&p, "natfreq", "warning", "drop", &l, err,
                                               sizeof err));
    assert_int_equal(0, amfi_level_rule_push(l, 9, &ev, &a));
    amfi_level_rule_destroy(l);
}

/* absolute, strict_raise: a drift either way; a median exactly at the
 * raise level does not raise, one beyond it does, on either side. */
static void test_absolute_strict(void **state)
{
    (void)state;
    amfi_level_params p = params(1, 0.02, 0.01, 1, 1);
    const char *field = NULL;
    char err[160];
    p.absolute = 1;
    p.strict_raise = 1;
    amfi_level_rule *l = NULL;
    assert_int_equal(0, amfi_level_rule_create(&p, "speed_drift", "info", "c", &l, err,
                                               sizeof err));
    amfi_level_eval ev;
    amfi_alert_event a;
    assert_int_equal(AMFI_IND_EVAL, amfi_level_rule_push(l, -0.02, &ev, &a));
    assert_int_equal(AMFI_IND_EVAL | AMFI_IND_ALERT, amfi_level_rule_push(l, -0.03, &ev, &a));
    assert_int_equal(1, a.raised);
    assert_non_null(strstr(a.message, "beyond +/-0.02"));
    assert_int_equal(AMFI_IND_EVAL, amfi_level_rule_push(l, 0.015, &ev, &a));
    assert_int_equal(AMFI_IND_EVAL | AMFI_IND_ALERT, amfi_level_rule_push(l, -0.005, &ev, &a));
    assert_int_equal(0, a.raised);
    assert_non_null(strstr(a.message, "within +/-0.01"));
    assert_int_equal(AMFI_IND_EVAL | AMFI_IND_ALERT, amfi_level_rule_push(l, 0.025, &ev, &a));
    amfi_level_rule_destroy(l);
    /* not strict: at the level raises */
    p.strict_raise = 0;
    assert_int_equal(0, amfi_level_rule_create(&p, "k", "info", "c", &l, err, sizeof err));
    assert_int_equal(AMFI_IND_EVAL | AMFI_IND_ALERT, amfi_level_rule_push(l, -0.02, &ev, &a));
    amfi_level_rule_destroy(l);
    /* |median| is never below a clear level of 0; modes are 0 or 1 */
    p.clear = 0;
    assert_int_equal(AMFI_IND_EINVAL, amfi_level_params_check(&p, &field, err, sizeof err));
    assert_string_equal("clear", field);
    p.clear = 0.01;
    p.absolute = 2;
    assert_int_equal(AMFI_IND_EINVAL, amfi_level_params_check(&p, &field, err, sizeof err));
    assert_string_equal("absolute", field);
    p.absolute = 0;
    p.strict_raise = -1;
    assert_int_equal(AMFI_IND_EINVAL, amfi_level_params_check(&p, &field, err, sizeof err));
    assert_string_equal("strict_raise", field);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_params),
        cmocka_unit_test(test_params_text),
        cmocka_unit_test(test_raise_clear),
        cmocka_unit_test(test_broken_streak),
        cmocka_unit_test(test_restore_and_refusals),
        cmocka_unit_test(test_absolute_strict),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
