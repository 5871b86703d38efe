/* test_interp_probe.c: G38.2..G38.5 against the probe model (plane, block) and a machine's
 * answer: where the probe trips, #5061..#5066 and #5070, where the program goes on from,
 * and the errors of a probe that does not trip or is tripped at the start. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "interp/interp.h"
#include "interp/probe_model.h"
#include "test_interp_util.h"

/* Material below z = -3 mm (machine frame). */
static struct probe_model plane_z(double z)
{
    struct probe_model m = { .kind = PROBE_MODEL_PLANE };
    m.point_mm[2] = z;
    m.normal[2] = 1;
    return m;
}

static struct probe_model block(void)
{
    struct probe_model m = { .kind = PROBE_MODEL_BOX };
    const double lo[3] = { 10, 20, -30 }, hi[3] = { 40, 50, 0 };
    memcpy(m.min_mm, lo, sizeof lo);
    memcpy(m.max_mm, hi, sizeof hi);
    return m;
}

START_TEST(plane_find)
{
    struct probe_model m = plane_z(-3);
    const double a[3] = { 0, 0, 7 }, b[3] = { 0, 0, -13 }, c[3] = { 5, 0, -1 };
    ck_assert_double_eq_tol(probe_model_find(&m, a, b, true), 0.5, 1e-12);  /* 10 of 20 mm */
    ck_assert_double_eq_tol(probe_model_find(&m, a, c, true), -1, 1e-15);       /* stays above */
    ck_assert_double_eq_tol(probe_model_find(&m, b, a, false), 0.5, 1e-12); /* leaves it */
    ck_assert_double_eq_tol(probe_model_find(&m, b, a, true), 0, 1e-15);        /* in it at once */
    /* a slanted plane through the origin, normal (1, 0, 1)/sqrt 2 */
    struct probe_model s = { .kind = PROBE_MODEL_PLANE, .normal = { M_SQRT1_2, 0, M_SQRT1_2 } };
    const double d[3] = { 4, 0, 4 }, e[3] = { -4, 0, -4 };
    ck_assert_double_eq_tol(probe_model_find(&s, d, e, true), 0.5, 1e-12);
}
END_TEST

START_TEST(box_find)
{
    struct probe_model m = block();
    const double above[3] = { 20, 30, 10 }, below[3] = { 20, 30, -10 };
    ck_assert_double_eq_tol(probe_model_find(&m, above, below, true), 0.5, 1e-12);
    const double side[3] = { 0, 30, -10 }, in[3] = { 20, 30, -10 };
    ck_assert_double_eq_tol(probe_model_find(&m, side, in, true), 0.5, 1e-12);  /* x = 10 */
    ck_assert_double_eq_tol(probe_model_find(&m, in, side, false), 0.5, 1e-12); /* leaves */
    const double miss[3] = { 0, 0, -10 }, miss2[3] = { 5, 60, -10 };
    ck_assert_double_eq_tol(probe_model_find(&m, miss, miss2, true), -1, 1e-15);
    /* the block lies behind the move, on its line: not reached */
    const double away_from[3] = { 20, 30, 20 }, away_to[3] = { 20, 30, 40 };
    ck_assert_double_eq_tol(probe_model_find(&m, away_from, away_to, true), -1, 1e-15);
    const double far[3] = { 20, 30, -20 };
    ck_assert_double_eq_tol(probe_model_find(&m, in, far, false), -1, 1e-15);    /* stays in */
    ck_assert(probe_model_contact(&m, in));
    ck_assert(!probe_model_contact(&m, above));
}
END_TEST

/* An INI in memory: up to 6 [PROBE] key = value entries. */
static const char *fake_get(void *ctx, const char *section, const char *key)
{
    const char *const *kv = ctx;
    for (int i = 0; kv[i]; i += 2)
        if (!strcmp(section, "PROBE") && !strcmp(kv[i], key))
            return kv[i + 1];
    return NULL;
}

/* Reads a model; returns its error text ("" when it was read). */
static const char *read_err(const char *const *kv, struct probe_model *m)
{
    static char err[300];
    err[0] = '\0';
    if (probe_model_read(m, fake_get, (void *)kv, err, sizeof err) == 0)
        ck_assert_str_eq(err, "");
    else
        ck_assert_str_ne(err, "");
    return err;
}

START_TEST(model_read)
{
    struct probe_model m;
    const char *none[] = { NULL };
    ck_assert_str_eq(read_err(none, &m), "");
    ck_assert_int_eq(m.kind, PROBE_MODEL_NONE);
    const char *plane[] = { "MODEL", "plane", "PLANE_POINT", "1 2 3", "PLANE_NORMAL", "0 0 2",
                            NULL };
    ck_assert_str_eq(read_err(plane, &m), "");
    ck_assert_int_eq(m.kind, PROBE_MODEL_PLANE);
    ck_assert_double_eq_tol(m.normal[2], 1, 1e-15);   /* made a unit vector */
    const char *bad[] = { "MODEL", "SPHERE", NULL };
    ck_assert_ptr_nonnull(strstr(read_err(bad, &m), "MODEL = SPHERE"));
    const char *missing[] = { "MODEL", "BOX", "BOX_MIN", "0 0 0", NULL };
    ck_assert_ptr_nonnull(strstr(read_err(missing, &m), "BOX_MAX"));
    const char *inverted[] = { "MODEL", "BOX", "BOX_MIN", "0 0 0", "BOX_MAX", "1 -1 1", NULL };
    ck_assert_ptr_nonnull(strstr(read_err(inverted, &m), "Y is 0 .. -1"));
    const char *foreign[] = { "MODEL", "BOX", "BOX_MIN", "0 0 0", "BOX_MAX", "1 1 1",
                              "PLANE_NORMAL", "0 0 1", NULL };
    ck_assert_ptr_nonnull(strstr(read_err(foreign, &m), "PLANE_NORMAL"));
    const char *flat[] = { "MODEL", "PLANE", "PLANE_POINT", "0 0 0", "PLANE_NORMAL", "0 0 0",
                           NULL };
    ck_assert_ptr_nonnull(strstr(read_err(flat, &m), "no length"));
    const char *text[] = { "MODEL", "PLANE", "PLANE_POINT", "0 0", "PLANE_NORMAL", "0 0 1",
                           NULL };
    ck_assert_ptr_nonnull(strstr(read_err(text, &m), "PLANE_POINT = 0 0"));
}
END_TEST

/* Runs text on an interpreter with model m; e gets the error. */
static int run_model(const struct probe_model *m, const char *text, struct canon_prog *p,
                     struct interp_error *e)
{
    struct interp *in = interp_create();
    ck_assert_ptr_nonnull(in);
    interp_set_probe_model(in, m);
    int rc = run_on(in, text, p);
    *e = *interp_last_error(in);
    interp_destroy(in);
    return rc;
}

START_TEST(model_plane_program)
{
    struct probe_model m = plane_z(-3);
    struct canon_prog p;
    struct interp_error e;
    /* G54 Z offset 2: the surface is at program Z -5; the probe stops on it */
    int rc = run_model(&m, "G21 F100\nG10 L2 P1 Z2\nG0 X1 Y2 Z10\nG38.2 Z-20\n"
                       "G1 X#5061 Y[#5062 + 1] Z[#5063 + 10 * #5070]\nG91 G1 X0.5\nM2\n", &p, &e);
    ck_assert_msg(rc == INTERP_OK, "%s", e.message);
    const struct canon_cmd *pr = nth(&p, CANON_PROBE, 0);
    ck_assert_pose(pr->end, 1, 2, -18, 0, 0, 0, 1e-12);         /* the programmed end */
    ck_assert_pose(pr->probe_stop, 1, 2, -3, 0, 0, 0, 1e-12);   /* where the model trips */
    ck_assert_int_eq(pr->ivalue, 0);
    ck_assert_double_eq(pr->inverse_time_min, 0);
    ck_assert_pose(nth(&p, CANON_FEED, 0)->end, 1, 3, 7, 0, 0, 0, 1e-12); /* #5063 = -5 */
    ck_assert_pose(nth(&p, CANON_FEED, 1)->end, 1.5, 3, 7, 0, 0, 0, 1e-12);
    canon_prog_free(&p);
    /* G38.2 that never reaches the plane: an error naming the line */
    rc = run_model(&m, "G21 F100\nG0 Z10\nG38.2 Z0\nM2\n", &p, &e);
    ck_assert_int_eq(rc, INTERP_ERR_PROBE);
    ck_assert_int_eq(e.line, 3);
    ck_assert_str_eq(e.message, "G38.2: the move ended without the probe touching anything");
    canon_prog_free(&p);
    /* G93: the probe move carries the whole move's time, 1/F minutes */
    rc = run_model(&m, "G21 F100\nG0 Z10\nG93 G38.2 Z-10 F4\nM2\n", &p, &e);
    ck_assert_msg(rc == INTERP_OK, "%s", e.message);
    ck_assert_double_eq_tol(nth(&p, CANON_PROBE, 0)->inverse_time_min, 0.25, 1e-15);
    canon_prog_free(&p);
    /* G38.3: no error; #5070 = 0 and the program goes on from the end */
    rc = run_model(&m, "G21 F100\nG0 Z10\nG38.3 Z0\nG1 X[#5070 + 1]\nM2\n", &p, &e);
    ck_assert_msg(rc == INTERP_OK, "%s", e.message);
    ck_assert_pose(nth(&p, CANON_FEED, 0)->end, 1, 0, 0, 0, 0, 0, 1e-12);
    canon_prog_free(&p);
    /* G38.2 in the material: tripped at the start */
    rc = run_model(&m, "G21 F100\nG0 Z-4\nG38.2 Z-10\nM2\n", &p, &e);
    ck_assert_int_eq(rc, INTERP_ERR_PROBE);
    ck_assert_int_eq(e.line, 3);
    ck_assert_ptr_nonnull(strstr(e.message, "already touches"));
    canon_prog_free(&p);
    /* G38.3 there: trips at once, where it starts */
    rc = run_model(&m, "G21 F100\nG0 Z-4\nG38.3 Z-10\nG1 X[10 * #5070] Z#5063\nM2\n", &p, &e);
    ck_assert_msg(rc == INTERP_OK, "%s", e.message);
    ck_assert_pose(nth(&p, CANON_FEED, 0)->end, 10, 0, -4, 0, 0, 0, 1e-12);
    canon_prog_free(&p);
}
END_TEST

START_TEST(model_box_away)
{
    struct probe_model m = block();
    struct canon_prog p;
    struct interp_error e;
    /* in inches: from inside the block, G38.4 along -X leaves it at x = 10 mm */
    int rc = run_model(&m, "G20 F10\nG0 X[20/25.4] Y[30/25.4] Z[-10/25.4]\nG38.4 X0\n"
                       "G21 G1 X[#5061 * 25.4 + 1] Y#5070\nM2\n", &p, &e);
    ck_assert_msg(rc == INTERP_OK, "%s", e.message);
    ck_assert_pose(nth(&p, CANON_PROBE, 0)->probe_stop, 10, 30, -10, 0, 0, 0, 1e-9);
    ck_assert_int_eq(nth(&p, CANON_PROBE, 0)->ivalue, 2);
    ck_assert_pose(nth(&p, CANON_FEED, 0)->end, 11, 1, -10, 0, 0, 0, 1e-9);
    canon_prog_free(&p);
    /* onto the block's top (Z0) and back up: on its surface the probe touches, so G38.4 is
     * not "already clear"; it leaves at once, where it starts */
    rc = run_model(&m, "G21 F10\nG0 X20 Y30 Z5\nG38.2 Z-5\nG38.4 Z5\n"
                   "G1 X[#5063 + 1] Y[#5070 * 2]\nM2\n", &p, &e);
    ck_assert_msg(rc == INTERP_OK, "%s", e.message);
    ck_assert_pose(nth(&p, CANON_FEED, 0)->end, 1, 2, 0, 0, 0, 0, 1e-12);
    canon_prog_free(&p);
    /* G38.4 from outside: already clear */
    rc = run_model(&m, "G21 F10\nG38.4 X5\nM2\n", &p, &e);
    ck_assert_int_eq(rc, INTERP_ERR_PROBE);
    ck_assert_ptr_nonnull(strstr(e.message, "already clear"));
    canon_prog_free(&p);
    /* G38.5 from outside: trips at once (#5070 = 1) */
    rc = run_model(&m, "G21 F10\nG38.5 X5\nG1 Y#5070\nM2\n", &p, &e);
    ck_assert_msg(rc == INTERP_OK, "%s", e.message);
    ck_assert_pose(nth(&p, CANON_FEED, 0)->end, 0, 1, 0, 0, 0, 0, 1e-15);
    canon_prog_free(&p);
}
END_TEST

/* A machine that trips 40 % of the way and comes to rest 60 % of the way; "no" refuses. */
struct fake_machine {
    int calls;
    int refuse;
};

static int fake_probe(void *ctx, const struct canon_cmd *c, struct interp_probe_result *r,
                      char *why, size_t whylen)
{
    struct fake_machine *f = ctx;
    f->calls++;
    if (f->refuse) {
        snprintf(why, whylen, "the probe input is already tripped");
        return -1;
    }
    static const double from[6] = { 0, 0, 10, 0, 0, 0 };
    r->tripped = 1;
    for (int i = 0; i < 6; i++) {
        r->trip[i] = from[i] + 0.4 * (c->end[i] - from[i]);
        r->stop[i] = from[i] + 0.6 * (c->end[i] - from[i]);
    }
    return 0;
}

START_TEST(machine_answer)
{
    struct fake_machine f = { 0, 0 };
    struct interp *in = interp_create();
    interp_set_probe_fn(in, fake_probe, &f);
    /* a model that has the probe in the material from the start: the machine's answer
     * counts, not the model's refusal */
    struct probe_model deep = plane_z(100);
    interp_set_probe_model(in, &deep);
    struct canon_prog p;
    /* G55 X offset 5: #5061 is in program coordinates; the next move starts at the stop */
    int rc = run_on(in, "G21 F100\nG10 L2 P2 X5\nG55\nG0 X-5 Y0 Z10\nG38.2 Z-10 A20\n"
                    "G1 Y[#5070 * 7] X#5061 A#5064\nG91 G1 Z1\nM2\n", &p);
    ck_assert_msg(rc == INTERP_OK, "%s", interp_last_error(in)->message);
    ck_assert_int_eq(f.calls, 1);
    ck_assert_pose(nth(&p, CANON_FEED, 0)->end, 0, 7, -2, 8, 0, 0, 1e-12);
    ck_assert_pose(nth(&p, CANON_FEED, 1)->end, 0, 7, -1, 8, 0, 0, 1e-12);
    canon_prog_free(&p);
    f.refuse = 1;
    rc = run_on(in, "G21 F100\nG38.4 X3\nM2\n", &p);
    ck_assert_int_eq(rc, INTERP_ERR_PROBE);
    ck_assert_int_eq(interp_last_error(in)->line, 2);
    ck_assert_str_eq(interp_last_error(in)->message,
                     "G38.4: the probe input is already tripped");
    canon_prog_free(&p);
    interp_destroy(in);
}
END_TEST

static Suite *probe_suite(void)
{
    Suite *s = suite_create("interp_probe");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, plane_find);
    tcase_add_test(tc, box_find);
    tcase_add_test(tc, model_read);
    tcase_add_test(tc, model_plane_program);
    tcase_add_test(tc, model_box_away);
    tcase_add_test(tc, machine_answer);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(probe_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? 1 : 0;
}
