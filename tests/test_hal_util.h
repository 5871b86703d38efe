/* test_hal_util.h: helpers shared by the tests that build HAL graphs and machines. */
#ifndef HEXCNC_TEST_HAL_UTIL_H
#define HEXCNC_TEST_HAL_UTIL_H

#include <check.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "hal/hal.h"

/* A path under the source tree (make test sets HEXCNC_ROOT; else the current folder). */
static inline void test_root_path(char *buf, size_t len, const char *rel)
{
    const char *root = getenv("HEXCNC_ROOT");
    snprintf(buf, len, "%s/%s", root ? root : ".", rel);
}

/* A pin's current data (its signal's when linked), which must have type `want`. */
static inline void *test_pin(struct hal *h, const char *name, enum hal_type want)
{
    enum hal_type t;
    void *p = hal_data_ptr(h, name, &t);
    ck_assert_msg(p != NULL, "no pin %s", name);
    ck_assert_int_eq(t, want);
    return p;
}

/* A pin's value of any type, as a double. */
static inline double test_pin_value(struct hal *h, const char *name)
{
    enum hal_type t;
    void *p = hal_data_ptr(h, name, &t);
    ck_assert_msg(p != NULL, "no pin %s", name);
    switch (t) {
    case HAL_BIT: return *(bool *)p;
    case HAL_S32: return *(int32_t *)p;
    case HAL_U32: return *(uint32_t *)p;
    case HAL_FLOAT: break;
    }
    return *(double *)p;
}

#endif
