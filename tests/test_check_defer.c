/* test_check_defer.c: the servo-rate pass's measures computed by another thread: applied in
 * the order they were taken, with the values the pass computes alone. */
#include <check.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check/check_defer.h"
#include "kins/kins_svd.h"
#include "tests/test_check_util.h"

#define TMU_INI "configs/sim/tmu-hexapod.ini"
#define MEASURES 60000           /* several times the ring: it fills and wraps */

/* The helper: computes whatever waits until told to stop. */
struct helper {
    struct check_defer *d;
    _Atomic int stop;
    long done;
};

static void *help(void *arg)
{
    struct helper *h = arg;
    while (!atomic_load(&h->stop))
        h->done += check_defer_work(h->d);
    return NULL;
}

/* The pose of measure i along a wandering path. */
static void pose_of(int i, double pose[6])
{
    double a = 1e-3 * i;
    double p[6] = { 40 * sin(a), 30 * cos(1.3 * a), 640 + 5 * sin(0.7 * a), 5 * sin(0.9 * a),
                    4 * cos(1.1 * a), 6 * sin(0.5 * a) };
    memcpy(pose, p, sizeof p);
}

/* Measure i (a deviation, a condition number or a move's end, by turns); its line is i, so
 * the order it comes back in shows. */
static void fill(struct check_defer_slot *q, struct kins *k, int i)
{
    double pose[6];
    pose_of(i, pose);
    q->line = i, q->file = "t.ngc", q->time_s = 1e-3 * i, q->dist_mm = i;
    memcpy(q->pose, pose, sizeof pose);
    if (q->kind == CHECK_DEFER_DEVIATION) {
        for (int j = 0; j < 6; j++)
            q->p0[j] = pose[j] - 0.02 * (j + 1) * 1e-2;
        ck_assert_int_eq(kins_inverse(k, q->p0, q->L0), KINS_OK);
        ck_assert_int_eq(kins_inverse(k, pose, q->L1), KINS_OK);
        q->tool_len_mm = 60;
        q->tip_mode = i % 5 == 0 ? CHECK_TIP_CHORD : i % 5 == 1 ? CHECK_TIP_LINE
                                                                 : CHECK_TIP_NONE;
        for (int j = 0; j < 3; j++)
            q->t0[j] = pose[j], q->t1[j] = pose[j] + 1;
    } else if (q->kind == CHECK_DEFER_FLUSH) {
        q->value = i;                    /* nothing to compute: passed through as it is */
    }
}

/* What slot q gives: its value, or the condition number of its matrix (as the pass would
 * solve it: the same bits as kins_check_pose's). */
static double value_of(const struct check_defer_slot *q)
{
    double cond = -1;
    if (q->kind != CHECK_DEFER_CONDITION || !q->has_m)
        return q->value;
    ck_assert(q->ok);
    ck_assert_int_eq(kins_svd_condition(q->m, 6, KINS_POSE_DIM, &cond), 0);
    return cond;
}

/* All measures through the ring, applied as they become ready (and when it is full), with a
 * helper thread or without; their lines and values into line[] and value[]. */
static void run(struct kins *k, int with_helper, int *line, double *value, double *tip)
{
    struct kins_tool_frame tf;
    ck_assert_int_eq(kins_get_tool_frame(k, &tf), KINS_OK);
    struct check_defer *d = check_defer_new(k, &tf, 0);
    ck_assert(d != NULL);
    struct helper h = { .d = d };
    pthread_t th;
    if (with_helper)
        ck_assert_int_eq(pthread_create(&th, NULL, help, &h), 0);
    int n = 0;
    const struct check_defer_slot *q;
    for (int i = 0; i < MEASURES; i++) {
        enum check_defer_kind kind = i % 3 == 0 ? CHECK_DEFER_DEVIATION
                                   : i % 3 == 1 ? CHECK_DEFER_CONDITION : CHECK_DEFER_FLUSH;
        struct check_defer_slot *s;
        while (!(s = check_defer_push(d, kind))) {
            q = check_defer_next(d, 1);
            line[n] = q->line, value[n] = value_of(q), tip[n++] = q->tip;
        }
        fill(s, k, i);
        check_defer_commit(d);
        while ((q = check_defer_next(d, 0)))
            line[n] = q->line, value[n] = value_of(q), tip[n++] = q->tip;
    }
    while ((q = check_defer_next(d, 1)))
        line[n] = q->line, value[n] = value_of(q), tip[n++] = q->tip;
    ck_assert_int_eq(n, MEASURES);
    if (with_helper) {
        atomic_store(&h.stop, 1);
        pthread_join(th, NULL);
        printf("deferred measures: the helper computed %ld of %d\n", h.done, MEASURES);
    }
    check_defer_free(d);
}

/* In order, and the same values whichever thread computed them. */
START_TEST(test_defer_order_and_values)
{
    char ip[1024], err[1024];
    struct check_machine *mc;
    ck_assert_msg(check_machine_open(tc_path(TMU_INI, ip, sizeof ip), &mc, err, sizeof err) == 0,
                  "%s", err);
    struct kins *k = check_machine_kins(mc);
    int *l1 = malloc(MEASURES * sizeof *l1), *l2 = malloc(MEASURES * sizeof *l2);
    double *v1 = malloc(MEASURES * sizeof *v1), *v2 = malloc(MEASURES * sizeof *v2);
    double *t1 = malloc(MEASURES * sizeof *t1), *t2 = malloc(MEASURES * sizeof *t2);
    ck_assert(l1 && l2 && v1 && v2 && t1 && t2);
    run(k, 0, l1, v1, t1);
    run(k, 1, l2, v2, t2);
    for (int i = 0; i < MEASURES; i++) {
        ck_assert_int_eq(l1[i], i);
        ck_assert_int_eq(l2[i], i);
        ck_assert_msg(v1[i] == v2[i], "measure %d: %.17g alone, %.17g with the helper", i,
                      v1[i], v2[i]);
        if (i % 3 == 0 && i % 5 < 2)
            ck_assert(t1[i] == t2[i]);
        if (i % 3 == 1) {                         /* condition numbers of the TMU, as */
            struct kins_check ck;                 /* the kinematics' check gives them */
            ck_assert(v1[i] > 1 && v1[i] < 50);
            double pose[6];
            pose_of(i, pose);
            ck_assert_int_eq(kins_check_pose(k, pose, &ck), KINS_OK);
            ck_assert(v1[i] == ck.condition);
        }
        if (i % 3 == 2)
            ck_assert(v1[i] == i);
    }
    free(l1), free(l2), free(v1), free(v2), free(t1), free(t2);
    check_machine_close(mc);
}
END_TEST

/* The pass takes a value that needs no computing without taking the measures behind it:
 * those wait for the helper (and once it must wait, it computes a run of them itself). */
START_TEST(test_defer_value_alone)
{
    char ip[1024], err[1024];
    struct check_machine *mc;
    ck_assert_msg(check_machine_open(tc_path(TMU_INI, ip, sizeof ip), &mc, err, sizeof err) == 0,
                  "%s", err);
    struct kins *k = check_machine_kins(mc);
    struct kins_tool_frame tf;
    ck_assert_int_eq(kins_get_tool_frame(k, &tf), KINS_OK);
    struct check_defer *d = check_defer_new(k, &tf, 0);
    ck_assert(d != NULL);
    for (int i = 0; i < 6; i++) {
        struct check_defer_slot *s = check_defer_push(d, i == 0 ? CHECK_DEFER_FLUSH
                                                                : CHECK_DEFER_DEVIATION);
        ck_assert(s != NULL);
        fill(s, k, i);
        check_defer_commit(d);
    }
    const struct check_defer_slot *q = check_defer_next(d, 0);
    ck_assert(q != NULL && q->line == 0);
    ck_assert_int_eq(atomic_load(&d->claim), 1);       /* the value alone */
    ck_assert(check_defer_next(d, 0) == NULL);           /* the measure waits */
    ck_assert_int_eq(check_defer_work(d), 1);            /* the helper takes one */
    q = check_defer_next(d, 0);
    ck_assert(q != NULL && q->line == 1 && q->ok);
    q = check_defer_next(d, 1);                          /* the pass must go on: it */
    ck_assert(q != NULL && q->line == 2);                /* computes the rest at once */
    ck_assert_int_eq(atomic_load(&d->claim), 6);
    for (int i = 3; i < 6; i++) {
        q = check_defer_next(d, 0);
        ck_assert(q != NULL && q->line == i && q->ok);
    }
    ck_assert(check_defer_next(d, 0) == NULL);
    check_defer_free(d);
    check_machine_close(mc);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("check_defer");
    TCase *tc = tcase_create("defer");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_defer_order_and_values);
    tcase_add_test(tc, test_defer_value_alone);
    suite_add_tcase(s, tc);
    SRunner *sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
