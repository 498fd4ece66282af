/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_speed_drift.c: unit tests of the speed-drift alert engine
 * (indicators/speed_drift.h): the parameter checks, the correction of two
 * speeds, the window (no evaluation until it is full, the oldest leaving
 * it), the median (odd and even W), one raise and one clear with the
 * hysteresis between them, no alert without estimated passages or when
 * disabled, the refill and the alert state restored after a restart, and
 * refused corrections changing nothing.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "speed_drift.h"

static amfi_speed_drift *make(int window, double threshold)
{
    amfi_speed_drift_params p;
    amfi_speed_drift *sd = NULL;
    char err[256];
    amfi_speed_drift_params_default(&p);
    p.window = window;
    p.threshold = threshold;
    assert_int_equal(0, amfi_speed_drift_create(&p, &sd, err, sizeof err));
    assert_non_null(sd);
    return sd;
}

static void test_params(void **state)
{
    (void)state;
    amfi_speed_drift_params p, q;
    const char *field = NULL;
    char err[256];
    amfi_speed_drift *sd = (amfi_speed_drift *)&p;
    amfi_speed_drift_params_default(&p);
    assert_int_equal(1, p.enabled);
    assert_int_equal(200, p.window);
    assert_true(p.threshold == 0.02);
    assert_int_equal(0, amfi_speed_drift_params_check(&p, &field, err, sizeof err));
    q = p;
    assert_int_equal(1, amfi_speed_drift_params_equal(&p, &q));
    q.threshold = 0.03;
    assert_int_equal(0, amfi_speed_drift_params_equal(&p, &q));

    static const struct {
        int enabled, window;
        double threshold;
        const char *field;
    } bad[] = {{2, 200, 0.02, "enabled"},  {1, 1, 0.02, "window"},  {1, 100001, 0.02, "window"},
               {1, 200, 0.0, "threshold"}, {1, 200, 0.51, "threshold"},
               {1, 200, NAN, "threshold"}, {1, 200, -0.02, "threshold"}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        q.enabled = bad[k].enabled;
        q.window = bad[k].window;
        q.threshold = bad[k].threshold;
        assert_int_equal(AMFI_IND_EINVAL, amfi_speed_drift_params_check(&q, &field, err, sizeof err));
        assert_string_equal(bad[k].field, field);
        assert_non_null(strstr(err, bad[k].field));
        assert_int_equal(AMFI_IND_EINVAL, amfi_speed_drift_create(&q, &sd, err, sizeof err));
        assert_null(sd);
        assert_non_null(strstr(err, bad[k].field));
    }
    amfi_speed_drift_destroy(NULL);
}

static void test_correction(void **state)
{
    (void)state;
    assert_true(fabs(amfi_speed_correction(24.0, 25.0) + 0.04) < 1e-15);
    assert_true(amfi_speed_correction(25.0, 25.0) == 0.0);
    assert_true(isnan(amfi_speed_correction(0.0, 25.0)));
    assert_true(isnan(amfi_speed_correction(25.0, 0.0)));
    assert_true(isnan(amfi_speed_correction(NAN, 25.0)));
    assert_true(isnan(amfi_speed_correction(25.0, INFINITY)));
    assert_true(isnan(amfi_speed_correction(-25.0, -25.0)));
}

/* No evaluation before the window is full; then the median of the last W. */
static void test_window_and_median(void **state)
{
    (void)state;
    amfi_speed_drift *sd = make(5, 0.5);
    amfi_speed_drift_eval ev = {0, 0};
    amfi_alert_event al;
    static const double c[] = {-0.05, 0.02, -0.04, 0.03, 0.01, 0.04, 0.05};
    for (int k = 0; k < 4; k++)
        assert_int_equal(0, amfi_speed_drift_push(sd, c[k], &ev, &al));
    assert_int_equal(AMFI_IND_EVAL, amfi_speed_drift_push(sd, c[4], &ev, &al));
    assert_int_equal(5, ev.n);
    assert_true(ev.median == 0.01); /* of −0.05 0.02 −0.04 0.03 0.01 */
    assert_int_equal(AMFI_IND_EVAL, amfi_speed_drift_push(sd, c[5], &ev, NULL));
    assert_true(ev.median == 0.02); /* −0.05 left: 0.02 −0.04 0.03 0.01 0.04 */
    assert_int_equal(AMFI_IND_EVAL, amfi_speed_drift_push(sd, c[6], &ev, NULL));
    assert_true(ev.median == 0.03); /* 0.02 left: −0.04 0.03 0.01 0.04 0.05 */
    assert_int_equal(5, ev.n);
    amfi_speed_drift_destroy(sd);

    /* even W: the mean of the two middle values */
    sd = make(4, 0.5);
    static const double e[] = {0.04, -0.02, 0.01, 0.02};
    for (int k = 0; k < 3; k++)
        assert_int_equal(0, amfi_speed_drift_push(sd, e[k], &ev, NULL));
    assert_int_equal(AMFI_IND_EVAL, amfi_speed_drift_push(sd, e[3], &ev, NULL));
    assert_int_equal(4, ev.n);
    assert_true(fabs(ev.median - 0.015) < 1e-15);
    amfi_speed_drift_destroy(sd);
}

/* A detector 4 % high: c = 1/1.04 − 1 = −3.85 %; raised once, at the push
 * where the median passes the threshold; cleared only below threshold / 2. */
static void test_raise_once_and_clear(void **state)
{
    (void)state;
    amfi_speed_drift *sd = make(5, 0.02);
    amfi_speed_drift_eval ev;
    amfi_alert_event al;
    int raised = 0, cleared = 0, at = -1;
    const double high = amfi_speed_correction(25.0, 26.0); /* −3.85 % */
    for (int k = 0; k < 5; k++)
        assert_false(amfi_speed_drift_push(sd, 0.001, &ev, &al) & AMFI_IND_ALERT);
    assert_false(amfi_speed_drift_alerted(sd));
    for (int k = 0; k < 20; k++) {
        memset(&al, 0, sizeof al);
        int bits = amfi_speed_drift_push(sd, high, &ev, &al);
        assert_true(bits & AMFI_IND_EVAL);
        if (bits & AMFI_IND_ALERT) {
            assert_int_equal(1, al.raised);
            assert_string_equal("info", al.level);
            assert_string_equal("speed_drift", al.kind);
            assert_non_null(strstr(al.message, "-3.85 %"));
            assert_non_null(strstr(al.message, "reads 4.0 % high"));
            raised++;
            at = k;
        }
    }
    assert_int_equal(1, raised);
    assert_int_equal(2, at); /* the third of five makes the median −3.85 % */
    assert_true(amfi_speed_drift_alerted(sd));
    /* −1.5 %: below the threshold but not below half of it: stays raised */
    for (int k = 0; k < 10; k++)
        assert_false(amfi_speed_drift_push(sd, -0.015, &ev, &al) & AMFI_IND_ALERT);
    assert_true(fabs(ev.median + 0.015) < 1e-15);
    assert_true(amfi_speed_drift_alerted(sd));
    /* −0.5 %: cleared once */
    for (int k = 0; k < 10; k++) {
        int bits = amfi_speed_drift_push(sd, -0.005, &ev, &al);
        if (bits & AMFI_IND_ALERT) {
            assert_int_equal(0, al.raised);
            assert_string_equal("speed_drift", al.kind);
            assert_non_null(strstr(al.message, "back within +/-1.00 %"));
            cleared++;
        }
    }
    assert_int_equal(1, cleared);
    assert_false(amfi_speed_drift_alerted(sd));
    /* a detector reading low raises too, the other way */
    int again = 0;
    for (int k = 0; k < 5; k++)
        if (amfi_speed_drift_push(sd, 0.05, &ev, &al) & AMFI_IND_ALERT) {
            again++;
            assert_non_null(strstr(al.message, "% low"));
        }
    assert_int_equal(1, again);
    amfi_speed_drift_destroy(sd);
}

/* No estimated passages: no push, no alert; disabled: pushes change nothing. */
static void test_none_and_disabled(void **state)
{
    (void)state;
    amfi_speed_drift *sd = make(3, 0.02);
    assert_false(amfi_speed_drift_alerted(sd));
    amfi_speed_drift_destroy(sd);

    amfi_speed_drift_params p;
    amfi_speed_drift_params_default(&p);
    p.enabled = 0;
    p.window = 3;
    char err[128];
    assert_int_equal(0, amfi_speed_drift_create(&p, &sd, err, sizeof err));
    amfi_alert_event al;
    amfi_speed_drift_eval ev = {-1, 0};
    for (int k = 0; k < 10; k++)
        assert_int_equal(0, amfi_speed_drift_push(sd, -0.2, &ev, &al));
    assert_int_equal(-1, ev.n);
    assert_false(amfi_speed_drift_alerted(sd));
    amfi_speed_drift_destroy(sd);
}

/* After a restart: the window refilled from the store, the open alert kept
 * (not raised a second time), refused values skipped. */
static void test_prefill_and_restore(void **state)
{
    (void)state;
    amfi_speed_drift *sd = make(4, 0.02);
    amfi_speed_drift_eval ev;
    amfi_alert_event al;
    static const double c[] = {-0.04, NAN, -0.04, 2.0, -0.04};
    assert_int_equal(3, amfi_speed_drift_prefill(sd, c, 5));
    assert_int_equal(AMFI_IND_EINVAL, amfi_speed_drift_prefill(sd, NULL, 1));
    assert_int_equal(AMFI_IND_EINVAL, amfi_speed_drift_prefill(sd, c, -1));
    assert_int_equal(0, amfi_speed_drift_prefill(sd, NULL, 0));
    amfi_speed_drift_set_alerted(sd, 1);
    assert_int_equal(AMFI_IND_EVAL, amfi_speed_drift_push(sd, -0.04, &ev, &al));
    assert_int_equal(4, ev.n);
    assert_true(fabs(ev.median + 0.04) < 1e-15);
    amfi_speed_drift_destroy(sd);

    /* the same without the restored state raises at once */
    sd = make(4, 0.02);
    amfi_speed_drift_prefill(sd, c, 5);
    assert_int_equal(AMFI_IND_EVAL | AMFI_IND_ALERT, amfi_speed_drift_push(sd, -0.04, &ev, &al));
    assert_int_equal(1, al.raised);
    amfi_speed_drift_destroy(sd);
}

static void test_refused(void **state)
{
    (void)state;
    amfi_speed_drift *sd = make(2, 0.02);
    amfi_speed_drift_eval ev = {-1, 0};
    static const double bad[] = {NAN, INFINITY, -1.0, 1.0, -3.0};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++)
        assert_int_equal(AMFI_IND_EINVAL, amfi_speed_drift_push(sd, bad[k], &ev, NULL));
    assert_int_equal(AMFI_IND_EINVAL, amfi_speed_drift_push(NULL, 0.0, &ev, NULL));
    /* nothing entered: two good values are needed for the first evaluation */
    assert_int_equal(0, amfi_speed_drift_push(sd, 0.0, &ev, NULL));
    assert_int_equal(AMFI_IND_EVAL, amfi_speed_drift_push(sd, 0.0, &ev, NULL));
    amfi_speed_drift_destroy(sd);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_params),
        cmocka_unit_test(test_correction),
        cmocka_unit_test(test_window_and_median),
        cmocka_unit_test(test_raise_once_and_clear),
        cmocka_unit_test(test_none_and_disabled),
        cmocka_unit_test(test_prefill_and_restore),
        cmocka_unit_test(test_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
