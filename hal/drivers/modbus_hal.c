/* modbus_hal.c: HAL component `modbus`: Modbus position drives (pins modbus.N.*, funct modbus.update). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "hal/hal.h"
#include "hal/drivers/drive_startup.h"
#include "hal/drivers/modbus_cfg.h"
#include "hal/drivers/modbus_link.h"

/*
 * A thin shell over modbus_link: `modbus.update` runs in the servo thread, posts each
 * drive's command into its mailbox and copies the latest feedback to the pins; it never
 * waits on the network. The exchanges happen in one I/O thread per drive (io=thread, the
 * default on the real-time clock) or, with the simulated clock (io=inline), in modbus.update
 * itself once every set-point period, so simulated runs are deterministic.
 *
 * After a fault stop a hexapod's legs must keep carrying the platform: while `hold` is true
 * (the e-stop latch's fault-out) and `enable` false, a drive that is not itself faulted
 * keeps ENABLE set with its target frozen at the command of the moment the hold began, so
 * it holds position under power; enable false without hold clears ENABLE (power stage off,
 * the drive's brake takes the load).
 *
 *   loadrt modbus [count=N] [section=MODBUS] [io=thread|inline]
 */

#define MODBUS_HAL_MAX_DRIVES 16

/* Pins and link of one drive. */
struct modbus_hal_drive {
    struct hal *h;            /* for messages to the shell (hal_msg_post) */
    char source[24];          /* "modbus.N", the messages' source */
    double *pos_cmd;          /* in: commanded position, mm */
    bool *enable;             /* in: enable the drive */
    bool *fault_reset;        /* in: rising edge clears the fault and reconnects */
    bool *hold;               /* in: while true and enable false, stay enabled holding */
    double *pos_fb;           /* out: actual position, mm */
    bool *fault;              /* out: latched communication or drive fault */
    bool *connected;          /* out: a connection is open */
    double *rtt_us;           /* out: last round trip, us */
    double *rtt_max_us;       /* out: largest round trip, us */
    uint32_t *errors;         /* out: failed connects and exchanges */
    uint32_t *status_word;    /* out: the drive's status word */
    bool reset_last;          /* fault-reset in the previous period (edge detection) */
    bool holding;             /* hold in force: ENABLE kept, target frozen at hold_mm */
    double hold_mm;           /* the command when the hold began, mm */
    long setpoint_ticks;      /* inline: servo periods per set-point period (0 = not yet) */
    long tick;                /* inline: servo periods since the last exchange */
    bool linked;              /* link initialised (needs fini) */
    struct modbus_link link;
};

/* The loaded component. */
struct modbus_hal {
    int count;                /* drives */
    bool inline_io;           /* exchanges in modbus.update instead of I/O threads */
    bool *fault_any;          /* out: any drive faulted (to the e-stop chain) */
    struct drive_startup startup;  /* for the runner: starting / ready / failed */
    struct modbus_hal_drive d[MODBUS_HAL_MAX_DRIVES];
};

/* Hands a fault to the shell once, when it is raised (from the I/O side); a fault before
 * the drive's first exchange is said to be one at start-up, with the drive's unit id. */
static void modbus_hal_report(void *arg, const char *msg)
{
    struct modbus_hal_drive *d = arg;
    struct modbus_feedback fb;
    modbus_link_feedback(&d->link, &fb);
    if (fb.exchanges == 0)
        hal_msg_post(d->h, HAL_MSG_FAULT, d->source, "%s (unit %d; at start-up, before its "
                     "first exchange)", msg, d->link.drive.cfg.unit);
    else
        hal_msg_post(d->h, HAL_MSG_FAULT, d->source, "%s", msg);
}

/* Starting until every drive has exchanged once, failed as soon as one has a fault. */
static void modbus_hal_startup(struct modbus_hal *c)
{
    int st = DRIVE_STARTUP_READY;
    for (int i = 0; i < c->count && st != DRIVE_STARTUP_FAILED; i++) {
        struct modbus_feedback fb;
        modbus_link_feedback(&c->d[i].link, &fb);
        if (fb.fault)
            st = DRIVE_STARTUP_FAILED;
        else if (fb.exchanges == 0)
            st = DRIVE_STARTUP_STARTING;
    }
    atomic_store(&c->startup.state, st);
}

/* The longest start-up the drives' settings allow: a connect and a first answer, each within
 * the response time-out, and two set-point periods, ns. */
static int64_t modbus_hal_startup_budget_ns(const struct modbus_hal *c)
{
    int64_t worst = 0;
    for (int i = 0; i < c->count; i++) {
        const struct modbus_drive_cfg *cfg = &c->d[i].link.drive.cfg;
        int64_t t = 2 * (int64_t)cfg->timeout_us * 1000 + 2 * (int64_t)cfg->period_ns;
        if (t > worst)
            worst = t;
    }
    return worst;
}

/* Copies drive d's latest feedback to its pins; returns its fault. */
static bool modbus_hal_publish(struct modbus_hal_drive *d)
{
    struct modbus_feedback fb;
    modbus_link_feedback(&d->link, &fb);
    *d->pos_fb = fb.pos_mm;
    *d->fault = fb.fault;
    *d->connected = fb.connected;
    *d->rtt_us = fb.rtt_us;
    *d->rtt_max_us = fb.rtt_max_us;
    *d->errors = fb.errors;
    *d->status_word = fb.status_word;
    return fb.fault;
}

/* Inline mode: true on the servo periods where drive d exchanges (the first, then every
 * SETPOINT_PERIOD / servo period, rounded, at least every period). */
static bool modbus_hal_due(struct modbus_hal_drive *d, long period_ns)
{
    if (!d->setpoint_ticks) {
        long sp = d->link.drive.cfg.period_ns;
        d->setpoint_ticks = period_ns > 0 ? (sp + period_ns / 2) / period_ns : 1;
        if (d->setpoint_ticks < 1)
            d->setpoint_ticks = 1;
    }
    bool due = d->tick == 0;
    d->tick = (d->tick + 1) % d->setpoint_ticks;
    return due;
}

/* The servo-thread function: commands in, feedback out, inline exchanges when configured. */
static void modbus_hal_update(void *arg, long period_ns)
{
    struct modbus_hal *c = arg;
    bool any = false;
    for (int i = 0; i < c->count; i++) {
        struct modbus_hal_drive *d = &c->d[i];
        if (*d->fault_reset && !d->reset_last)
            modbus_link_reset(&d->link);
        d->reset_last = *d->fault_reset;
        bool hold = *d->hold && !*d->enable && !*d->fault;
        if (hold && !d->holding)
            d->hold_mm = *d->pos_cmd;
        d->holding = hold;
        modbus_link_command(&d->link, hold ? d->hold_mm : *d->pos_cmd, *d->enable || hold);
        if (c->inline_io && modbus_hal_due(d, period_ns))
            modbus_link_cycle(&d->link);
        any = modbus_hal_publish(d) || any;
    }
    *c->fault_any = any;
    modbus_hal_startup(c);
}

/* Stops the I/O threads and closes the connections (hal_destroy). */
static void modbus_hal_free(void *arg)
{
    struct modbus_hal *c = arg;
    for (int i = 0; i < c->count; i++)
        if (c->d[i].linked)
            modbus_link_fini(&c->d[i].link);
    free(c);
}

/* Creates drive i's pins. */
static int modbus_hal_pins(struct hal *h, struct modbus_hal_drive *d, int i)
{
    int rc;
    if ((rc = hal_pin_float_newf(h, HAL_IN, &d->pos_cmd, "modbus.%d.position-cmd", i)) ||
        (rc = hal_pin_bit_newf(h, HAL_IN, &d->enable, "modbus.%d.enable", i)) ||
        (rc = hal_pin_bit_newf(h, HAL_IN, &d->fault_reset, "modbus.%d.fault-reset", i)) ||
        (rc = hal_pin_bit_newf(h, HAL_IN, &d->hold, "modbus.%d.hold", i)) ||
        (rc = hal_pin_float_newf(h, HAL_OUT, &d->pos_fb, "modbus.%d.position-fb", i)) ||
        (rc = hal_pin_bit_newf(h, HAL_OUT, &d->fault, "modbus.%d.fault", i)) ||
        (rc = hal_pin_bit_newf(h, HAL_OUT, &d->connected, "modbus.%d.connected", i)) ||
        (rc = hal_pin_float_newf(h, HAL_OUT, &d->rtt_us, "modbus.%d.rtt-us", i)) ||
        (rc = hal_pin_float_newf(h, HAL_OUT, &d->rtt_max_us, "modbus.%d.rtt-max-us", i)) ||
        (rc = hal_pin_u32_newf(h, HAL_OUT, &d->errors, "modbus.%d.errors", i)) ||
        (rc = hal_pin_u32_newf(h, HAL_OUT, &d->status_word, "modbus.%d.status-word", i)))
        return rc;
    return HAL_OK;
}

/* Parses count=, section= and io= into the outputs. */
static int modbus_hal_args(struct hal *h, int argc, char **argv, long *count, char *section,
                           size_t len, bool *inline_io)
{
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        if (!strncmp(a, "count=", 6)) {
            char *end;
            *count = strtol(a + 6, &end, 10);
            if (*end || *count < 1 || *count > MODBUS_HAL_MAX_DRIVES)
                return hal_error(h, HAL_ERR_ARG, "modbus: count must be 1..%d, not '%s'",
                                 MODBUS_HAL_MAX_DRIVES, a + 6);
        } else if (!strncmp(a, "section=", 8) && a[8] && strlen(a + 8) < len - 16) {
            snprintf(section, len, "%s", a + 8);
        } else if (!strcmp(a, "io=thread") || !strcmp(a, "io=inline")) {
            *inline_io = !strcmp(a, "io=inline");
        } else {
            return hal_error(h, HAL_ERR_ARG, "modbus: unknown argument '%s' (expected count=N, "
                             "section=NAME, io=thread or io=inline)", a);
        }
    }
    return HAL_OK;
}

/* Reads drive i's config from the INI and opens its link. */
static int modbus_hal_drive_new(struct hal *h, struct modbus_hal *c, int i, const char *section)
{
    struct modbus_drive_cfg cfg;
    char err[320];
    if (modbus_cfg_read(&cfg, i, section, hal_ini_lookup, h, hal_ini_path(h), err,
                        sizeof(err)))
        return hal_error(h, HAL_ERR_COMPONENT, "modbus: %s", err);
    if (c->inline_io)       /* simulated time: the load on the computer must not matter */
        cfg.wait_us = MODBUS_DRIVE_INLINE_WAIT_US;
    struct modbus_hal_drive *d = &c->d[i];
    if (modbus_link_init(&d->link, &cfg)) {
        snprintf(err, sizeof(err), "%s", modbus_drive_message(&d->link.drive));
        modbus_link_fini(&d->link);
        return hal_error(h, HAL_ERR_COMPONENT, "modbus: %s: %s",
                         hal_ini_path(h) ? hal_ini_path(h) : "INI", err);
    }
    d->linked = true;
    d->h = h;
    snprintf(d->source, sizeof d->source, "modbus.%d", i);
    d->link.report = modbus_hal_report;
    d->link.report_arg = d;
    return modbus_hal_pins(h, d, i);
}

/* The pins hold the drives' own positions before the servo thread first runs (motion checks
 * its following error from the first period): one read now inline, or a bounded wait for
 * each I/O thread's first read (a drive that cannot answer is faulted by then). */
static void modbus_hal_first_read(struct modbus_hal *c)
{
    bool any = false;
    for (int i = 0; i < c->count; i++) {
        struct modbus_hal_drive *d = &c->d[i];
        if (c->inline_io) {
            modbus_link_cycle(&d->link);
        } else {
            const struct modbus_drive_cfg *cfg = &d->link.drive.cfg;
            long wait_ms = cfg->timeout_us / 1000 + 2 * cfg->period_ns / 1000000 + 100;
            struct timespec nap = { 0, 1000000 };
            struct modbus_feedback fb = { 0 };
            for (long ms = 0; ms < wait_ms && !fb.exchanges && !fb.fault; ms++) {
                nanosleep(&nap, NULL);
                modbus_link_feedback(&d->link, &fb);
            }
        }
        any = modbus_hal_publish(d) || any;
    }
    *c->fault_any = any;
}

/* `loadrt modbus ...`: the drives, their pins, modbus.fault-any and modbus.update. */
static int modbus_hal_load(struct hal *h, int argc, char **argv)
{
    char section[48] = "MODBUS", err[200];
    bool inline_io = hal_sim_clock(h);
    long count = -1;
    int rc = modbus_hal_args(h, argc, argv, &count, section, sizeof(section), &inline_io);
    if (rc)
        return rc;
    if (count < 0) {
        count = modbus_cfg_drive_count(section, hal_ini_lookup, h, hal_ini_path(h), 1,
                                       MODBUS_HAL_MAX_DRIVES, err, sizeof(err));
        if (count < 0)
            return hal_error(h, HAL_ERR_COMPONENT, "modbus: %s", err);
    }
    struct modbus_hal *c = calloc(1, sizeof(*c));
    if (!c)
        return hal_error(h, HAL_ERR_NOMEM, "modbus: out of memory");
    if ((rc = hal_on_destroy(h, modbus_hal_free, c))) {
        free(c);
        return rc;
    }
    c->inline_io = inline_io;
    for (int i = 0; i < count; i++) {
        c->count = i + 1;
        if ((rc = modbus_hal_drive_new(h, c, i, section)))
            return rc;
    }
    if ((rc = hal_pin_bit_newf(h, HAL_OUT, &c->fault_any, "modbus.fault-any")) ||
        (rc = hal_export_functf(h, modbus_hal_update, c, "modbus.update")))
        return rc;
    for (int i = 0; !inline_io && i < c->count; i++)
        if (modbus_link_start(&c->d[i].link))
            return hal_error(h, HAL_ERR_RT, "modbus: drive %d: %s", i,
                             modbus_drive_strerror(MODBUS_DRIVE_ERR_THREAD));
    modbus_hal_first_read(c);
    modbus_hal_startup(c);
    c->startup.budget_ns = modbus_hal_startup_budget_ns(c);
    c->startup.what = "Modbus drives (modbus)";
    return hal_set_object(h, DRIVE_STARTUP_OBJ_MODBUS, &c->startup);
}

const struct hal_comp_type hal_comp_modbus = { "modbus", modbus_hal_load };
