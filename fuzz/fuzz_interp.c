/* fuzz_interp.c: libFuzzer target: any bytes as a program must give commands or a clean error. */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "interp/interp.h"
#include "interp/printer.h"
#include "interp/tooltable.h"
#include "kins/kins.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Discards the printed text (the printer's formatting is exercised all the same). */
static int discard(void *ctx, const char *buf, size_t len)
{
    (void)ctx;
    (void)buf;
    (void)len;
    return 0;
}

/* A small fixed tool table, so T, M6, G43 H and G141 D paths are reached too. */
static void fill_tools(struct tooltable *tt)
{
    tooltable_init(tt);
    for (int t = 1; t <= 3; t++) {
        struct tool_entry e;
        memset(&e, 0, sizeof e);
        e.tool = t;
        e.pocket = t;
        e.z_offset_mm = 10.0 * t;
        e.diameter_mm = 4.0 * t;
        tooltable_set(tt, &e);
    }
}

/* A fixed INI and HAL, so #<_ini[..]..> and #<_hal[..]> are reached with values and
 * without. */
static const char *fake_ini(void *ctx, const char *sec, const char *key)
{
    (void)ctx;
    if (!strcmp(sec, "TRAJ") && !strcmp(key, "MAX_LINEAR_VELOCITY"))
        return "100";
    if (!strcmp(sec, "TRAJ") && !strcmp(key, "COORDINATES"))
        return "X Y Z A B C";
    return NULL;
}

static int fake_hal(void *ctx, const char *name, double *v)
{
    (void)ctx;
    *v = (double)strlen(name);
    return name[0] == 'x' ? -1 : 0;
}

/* The TMU machine's tool (fixed on the frame, 60 mm below its gauge point), for G43.4. */
static const struct kins_tool_frame tmu_tool = { 0, { 0, 0, 780 }, { 0, 0, -1 }, 60, 0 };

/* One input: a fresh interpreter runs it through the printer; errors are fine, crashes not. */
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static struct tooltable tt;  /* the harness's only state; rebuilt for every input */
    static struct interp_printer pr;
    fill_tools(&tt);
    struct interp *in = interp_create();
    if (!in)
        return 0;
    interp_set_tooltable(in, &tt);
    interp_set_ini(in, fake_ini, NULL);
    interp_set_hal_fn(in, fake_hal, NULL);
    if (size & 2)              /* half the inputs may use G43.4 */
        interp_set_tool_frame(in, &tmu_tool);
    interp_set_block_delete(in, size & 1);
    interp_set_loop_limit(in, 10000);  /* a loop that never ends fails fast, not at 10^7 */
    interp_printer_init(&pr, in, 4, discard, NULL);
    interp_run_text(in, "fuzz.ngc", (const char *)data, size, interp_printer_sink, &pr);
    interp_printer_flush(&pr);
    char msg[600];
    interp_error_format(interp_last_error(in), msg, sizeof msg);
    interp_destroy(in);
    return 0;
}
