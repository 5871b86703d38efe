/* plugin_demo.c: a component built as a plugin (demo-plugin.so) for test_hal_plugin: it
 * doubles its input every period. */
#include <stdlib.h>

#include "hal/hal.h"

struct demo {
    double *in, *out;
};

static void demo_run(void *arg, long period_ns)
{
    struct demo *d = arg;
    *d->out = 2.0 * *d->in;
}

static int demo_load(struct hal *h, int argc, char **argv)
{
    int st = hal_args_check(h, "demo-plugin", argc, argv, "");
    if (st != HAL_OK)
        return st;
    struct demo *d = calloc(1, sizeof *d);
    if (!d || hal_on_destroy(h, free, d) != HAL_OK) {
        free(d);
        return hal_error(h, HAL_ERR_NOMEM, "demo-plugin: out of memory");
    }
    if ((st = hal_pin_float_newf(h, HAL_IN, &d->in, "demo-plugin.in")) != HAL_OK ||
        (st = hal_pin_float_newf(h, HAL_OUT, &d->out, "demo-plugin.out")) != HAL_OK)
        return st;
    return hal_export_functf(h, demo_run, d, "demo-plugin");
}

const struct hal_comp_type hal_comp_demo_plugin = { "demo-plugin", demo_load };
