/* test_interp_util.h: runs G-code text through an interpreter into a canon_prog for tests. */
#ifndef HEXCNC_TEST_INTERP_UTIL_H
#define HEXCNC_TEST_INTERP_UTIL_H

#include <check.h>
#include <math.h>
#include <string.h>

#include "interp/canon.h"
#include "interp/interp.h"

/* Runs text on interpreter in (fresh program), collecting commands in p; returns status. */
static inline int run_on(struct interp *in, const char *text, struct canon_prog *p)
{
    canon_prog_init(p);
    return interp_run_text(in, "t.ngc", text, strlen(text), canon_prog_sink, p);
}

/* The same on a new interpreter, destroyed afterwards; err receives its error. */
static inline int run_text(const char *text, struct canon_prog *p, struct interp_error *err)
{
    struct interp *in = interp_create();
    ck_assert_ptr_nonnull(in);
    int rc = run_on(in, text, p);
    if (err)
        *err = *interp_last_error(in);
    interp_destroy(in);
    return rc;
}

/* The k-th command of type t (k from 0); the test fails if there is none. */
static inline const struct canon_cmd *nth(const struct canon_prog *p, enum canon_type t, int k)
{
    static const struct canon_cmd none;
    int want = k;
    for (size_t i = 0; i < p->count; i++)
        if (p->cmds[i].type == t && k-- == 0)
            return &p->cmds[i];
    ck_abort_msg("no %s command number %d", canon_type_name(t), want);
    return &none;
}

static inline int count_type(const struct canon_prog *p, enum canon_type t)
{
    int n = 0;
    for (size_t i = 0; i < p->count; i++)
        n += p->cmds[i].type == t;
    return n;
}

/* The last move (TRAVERSE, FEED or ARC); the test fails if there is none. */
static inline const struct canon_cmd *last_move(const struct canon_prog *p)
{
    static const struct canon_cmd none;
    for (size_t i = p->count; i-- > 0;)
        if (p->cmds[i].type == CANON_TRAVERSE || p->cmds[i].type == CANON_FEED ||
            p->cmds[i].type == CANON_ARC)
            return &p->cmds[i];
    ck_abort_msg("no move");
    return &none;
}

/* Runs a program that must succeed; the failure message is the interpreter's error. */
static inline void interp_ok(const char *text, struct canon_prog *p)
{
    struct interp_error e;
    int rc = run_text(text, p, &e);
    ck_assert_msg(rc == INTERP_OK, "failed: %s:%d:%d: %s", e.file, e.line, e.column, e.message);
}

/* The status a program ends with (its commands are freed). */
static inline int interp_status_of(const char *text)
{
    struct canon_prog p;
    int rc = run_text(text, &p, NULL);
    canon_prog_free(&p);
    return rc;
}

#define ck_assert_pose(pose, x, y, z, a, b, c, tol) do {                              \
        const double *p_ = (pose);                                                    \
        const double e_[6] = {x, y, z, a, b, c};                                      \
        for (int i_ = 0; i_ < 6; i_++)                                                \
            ck_assert_double_eq_tol(p_[i_], e_[i_], tol);                             \
    } while (0)

#endif
