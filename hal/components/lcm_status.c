/* lcm_status.c: the `lcm-status` HAL component: pins, the servo-thread sample, events, API. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "common/config.h"
#include "hal/components/lcm_status_priv.h"

static const char lcm_axis_letter[LCM_AXES] = { 'x', 'y', 'z', 'a', 'b', 'c' };

/* Messages for enum lcm_status_status. */
const char *lcm_status_strerror(int status)
{
    static const char *const text[LCM_STATUS_STATUS_COUNT] = {
        [LCM_STATUS_OK] = "ok",
        [LCM_STATUS_NOT_LOADED] = "no lcm-status component is loaded",
        [LCM_STATUS_DISABLED] = "lcm-status is not publishing (no [LCM] URL, or it did not open)",
        [LCM_STATUS_FULL] = "the event queue is full; the event was dropped",
        [LCM_STATUS_TIMEOUT] = "the LCM publisher did not catch up in time",
    };
    return status >= 0 && status < LCM_STATUS_STATUS_COUNT ? text[status]
                                                           : "unknown lcm-status status";
}

/* CLOCK_MONOTONIC in ns. */
int64_t lcm_mono_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

/* Copies the input pins into a slot. */
static void lcm_fill(const struct lcm_status *s, struct lcm_sample *p)
{
    for (int i = 0; i < LCM_AXES; i++) {
        p->pose_cmd[i] = *s->pose_cmd[i];
        p->pose_fb[i] = *s->pose_fb[i];
    }
    for (int i = 0; i < LCM_LEGS; i++) {
        p->leg_cmd[i] = *s->leg_cmd[i];
        p->leg_fb[i] = *s->leg_fb[i];
        p->leg_rate[i] = *s->leg_rate[i];
        p->ferror[i] = *s->ferror[i];
    }
}

/* Pushes one slot of `kind` (no lock, no allocation; a full ring drops and counts). */
static void lcm_push(struct lcm_status *s, int32_t kind, uint32_t faults, uint32_t changed,
                     int64_t t_ns, int64_t mono_ns)
{
    /* A sample's number is taken even when it is dropped, so gaps show the loss. */
    int64_t seq = atomic_load_explicit(&s->seq, memory_order_relaxed);
    if (kind == LCM_SLOT_SAMPLE)
        atomic_store_explicit(&s->seq, seq + 1, memory_order_relaxed);
    struct lcm_sample *p = ring_spsc_claim(&s->samples);
    if (!p)
        return;
    p->kind = kind;
    p->state = *s->state;
    p->line = *s->line;
    p->faults = faults;
    p->changed = changed;
    p->t_ns = t_ns;
    p->mono_ns = mono_ns;
    p->sim = mono_ns == 0;
    p->seq = seq;
    lcm_fill(s, p);
    ring_spsc_commit(&s->samples);
}

/* lcm-status.sample, on the servo thread. Real time: every period goes into the ring and
 * the publisher keeps the newest per publish period. Simulated clock: one sample per
 * publish period of machine time, so the stream depends only on the machine, plus one at
 * once when the state input changes: the stop (done, fault, abort) is published with its
 * own time and state, not only at the next grid point, which a stopped run never reaches.
 * A change of any fault input goes in at once, whatever the decimation. */
static void lcm_sample_run(void *arg, long period_ns)
{
    struct lcm_status *s = arg;
    *s->sent = (uint32_t)atomic_load_explicit(&s->status_sent, memory_order_relaxed);
    *s->dropped = (uint32_t)ring_spsc_dropped(&s->samples);
    atomic_store_explicit(&s->last_line, *s->line, memory_order_relaxed);
    if (!s->lcm)
        return;
    bool sim = hal_sim_clock(s->h);
    atomic_store_explicit(&s->sim, sim, memory_order_relaxed);
    int64_t t_ns = hal_now_ns(s->h);
    int64_t mono_ns = sim ? 0 : lcm_mono_ns();
    if (t_ns < s->last_t_ns)        /* the threads were started again: time restarts */
        s->next_due_ns = 0;
    s->last_t_ns = t_ns;

    uint32_t faults = 0;
    for (int i = 0; i < s->nfaults; i++)
        faults |= (uint32_t)(*s->fault[i] ? 1u : 0u) << i;
    if (faults != s->last_faults)
        lcm_push(s, LCM_SLOT_EDGE, faults, faults ^ s->last_faults, t_ns, mono_ns);
    s->last_faults = faults;

    bool state_changed = *s->state != s->last_state;
    s->last_state = *s->state;
    if (sim) {
        if (t_ns < s->next_due_ns && !state_changed)
            return;
        /* The next sample on the grid of publish periods after now. */
        s->next_due_ns = (t_ns / s->period_ns + 1) * s->period_ns;
    }
    lcm_push(s, LCM_SLOT_SAMPLE, faults, 0, t_ns, mono_ns);
}

/* The instance of this runtime, or NULL. */
static struct lcm_status *lcm_find(struct hal *h)
{
    return h ? hal_get_object(h, LCM_STATUS_NAME) : NULL;
}

/* Queues an event for the publisher; safe from any thread (lock-free queue). */
int lcm_status_post_event(struct hal *h, enum lcm_status_severity severity, int32_t code,
                          const char *source, int32_t line, const char *fmt, ...)
{
    struct lcm_status *s = lcm_find(h);
    if (!s)
        return LCM_STATUS_NOT_LOADED;
    if (!s->lcm)
        return LCM_STATUS_DISABLED;
    struct lcm_event_slot e;
    memset(&e, 0, sizeof e);
    e.sim = hal_sim_clock(h);
    e.t_ns = hal_now_ns(h);
    e.mono_ns = e.sim ? 0 : lcm_mono_ns();
    e.severity = (int32_t)severity;
    e.code = code;
    e.line = line >= 0 ? line : atomic_load_explicit(&s->last_line, memory_order_relaxed);
    snprintf(e.source, sizeof e.source, "%s", source ? source : "");
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(e.text, sizeof e.text, fmt, ap);
    va_end(ap);
    return ring_mpsc_push(&s->events, &e) ? LCM_STATUS_OK : LCM_STATUS_FULL;
}

/* Counters; any thread. */
int lcm_status_get_stats(struct hal *h, struct lcm_status_stats *st)
{
    struct lcm_status *s = lcm_find(h);
    memset(st, 0, sizeof *st);
    if (!s)
        return LCM_STATUS_NOT_LOADED;
    st->samples = (uint64_t)atomic_load(&s->seq);
    st->samples_dropped = ring_spsc_dropped(&s->samples);
    st->status_sent = atomic_load(&s->status_sent);
    st->events_sent = atomic_load(&s->events_sent);
    st->events_dropped = ring_mpsc_dropped(&s->events);
    st->publish_errors = atomic_load(&s->publish_errors);
    return s->lcm ? LCM_STATUS_OK : LCM_STATUS_DISABLED;
}

/* Sleeps in 1 ms steps until the publisher has consumed what was pushed before the call. */
int lcm_status_flush(struct hal *h, int timeout_ms)
{
    struct lcm_status *s = lcm_find(h);
    if (!s)
        return LCM_STATUS_NOT_LOADED;
    if (!s->lcm)
        return LCM_STATUS_DISABLED;
    uint64_t want_s = ring_spsc_pushed(&s->samples), want_e = ring_mpsc_pushed(&s->events);
    struct timespec ms = { 0, 1000000 };
    for (int waited = 0;; waited++) {
        if (atomic_load(&s->samples_done) >= want_s && atomic_load(&s->events_done) >= want_e)
            return LCM_STATUS_OK;
        if (waited >= timeout_ms)
            return LCM_STATUS_TIMEOUT;
        nanosleep(&ms, NULL);
    }
}

/* The LCM instance (for memq:// tests). */
lcm_t *lcm_status_lcm(struct hal *h)
{
    struct lcm_status *s = lcm_find(h);
    return s ? s->lcm : NULL;
}

/* hal_destroy (or a failed loadrt): stop the publisher after a last drain, free all. */
static void lcm_status_free(void *arg)
{
    struct lcm_status *s = arg;
    lcm_pub_stop(s);
    if (s->lcm)
        lcm_destroy(s->lcm);
    ring_spsc_free(&s->samples);
    ring_mpsc_free(&s->events);
    free(s);
}

/* Input pins: pose, legs, state, line; fault inputs named by faults=. */
static int lcm_pins(struct hal *h, struct lcm_status *s)
{
    const char *n = LCM_STATUS_NAME;
    int st = HAL_OK;
    for (int i = 0; st == HAL_OK && i < LCM_AXES; i++) {
        st = hal_pin_float_newf(h, HAL_IN, &s->pose_cmd[i], "%s.pose-cmd-%c", n, lcm_axis_letter[i]);
        if (st == HAL_OK)
            st = hal_pin_float_newf(h, HAL_IN, &s->pose_fb[i], "%s.pose-fb-%c", n, lcm_axis_letter[i]);
    }
    for (int i = 0; st == HAL_OK && i < LCM_LEGS; i++) {
        st = hal_pin_float_newf(h, HAL_IN, &s->leg_cmd[i], "%s.leg-cmd-%d", n, i);
        if (st == HAL_OK)
            st = hal_pin_float_newf(h, HAL_IN, &s->leg_fb[i], "%s.leg-fb-%d", n, i);
        if (st == HAL_OK)
            st = hal_pin_float_newf(h, HAL_IN, &s->leg_rate[i], "%s.leg-rate-%d", n, i);
        if (st == HAL_OK)
            st = hal_pin_float_newf(h, HAL_IN, &s->ferror[i], "%s.ferror-%d", n, i);
    }
    if (st == HAL_OK) st = hal_pin_s32_newf(h, HAL_IN, &s->state, "%s.state", n);
    if (st == HAL_OK) st = hal_pin_s32_newf(h, HAL_IN, &s->line, "%s.line", n);
    for (int i = 0; st == HAL_OK && i < s->nfaults; i++)
        st = hal_pin_bit_newf(h, HAL_IN, &s->fault[i], "%s.fault-%s", n, s->fault_name[i]);
    if (st == HAL_OK) st = hal_pin_u32_newf(h, HAL_OUT, &s->sent, "%s.sent", n);
    if (st == HAL_OK) st = hal_pin_u32_newf(h, HAL_OUT, &s->dropped, "%s.dropped", n);
    if (st == HAL_OK) st = hal_pin_bit_newf(h, HAL_OUT, &s->active, "%s.active", n);
    return st;
}

/* faults=a,b,c: the names of the fault inputs (default: the simulated machine's). */
static int lcm_fault_names(struct hal *h, struct lcm_status *s, const char *list)
{
    for (const char *p = list; *p;) {
        size_t len = strcspn(p, ",");
        if (len == 0 || len >= LCM_FAULT_NAME_MAX || s->nfaults >= LCM_FAULTS_MAX)
            return hal_error(h, HAL_ERR_ARG, "loadrt lcm-status: faults=%s: a name is empty "
                             "or longer than %d characters, or there are more than %d",
                             list, LCM_FAULT_NAME_MAX - 1, LCM_FAULTS_MAX);
        memcpy(s->fault_name[s->nfaults], p, len);
        s->fault_name[s->nfaults++][len] = '\0';
        p += len + (p[len] == ',');
    }
    return HAL_OK;
}

/* url=, rate=, ring= from the arguments, else [LCM] URL / RATE_HZ from the INI. */
static int lcm_config(struct hal *h, struct lcm_status *s, int argc, char **argv, long *slots)
{
    const char *url = hal_arg(argc, argv, "url");
    if (!url)
        url = hal_ini_get(h, "LCM", "URL");
    if (url && strlen(url) >= sizeof s->url)
        return hal_error(h, HAL_ERR_ARG, "loadrt lcm-status: the LCM URL is longer than %zu "
                         "characters", sizeof s->url - 1);
    snprintf(s->url, sizeof s->url, "%s", url ? url : "");

    const char *rate = hal_arg(argc, argv, "rate");
    int st = HAL_OK;
    if (rate) {
        if (config_parse_number(rate, &s->rate_hz, NULL, 0) != 0)
            s->rate_hz = NAN;
    } else {
        st = hal_ini_double(h, "LCM", "RATE_HZ", 20.0, &s->rate_hz);
        if (st == HAL_ERR_NOT_FOUND)
            st = HAL_OK;
    }
    if (st != HAL_OK)
        return st;
    if (!(s->rate_hz > 0.0 && s->rate_hz <= 10000.0))
        return hal_error(h, HAL_ERR_ARG, "loadrt lcm-status: the publish rate must be a number "
                         "of messages per second above 0 and at most 10000 (rate= or [LCM] "
                         "RATE_HZ)");
    s->period_ns = (int64_t)llround(1e9 / s->rate_hz);

    const char *ring = hal_arg(argc, argv, "ring");
    *slots = LCM_RING_DEFAULT;
    if (ring) {
        if (config_parse_integer(ring, slots, NULL, 0) != 0 || *slots < 2 || *slots > (1L << 20) || (*slots & (*slots - 1)))
            return hal_error(h, HAL_ERR_ARG, "loadrt lcm-status: ring=%s: the ring size must "
                             "be a power of two from 2 to 1048576 samples", ring);
    }
    const char *faults = hal_arg(argc, argv, "faults");
    return lcm_fault_names(h, s, faults ? faults : "motion,kins,estop");
}

/* Opens the URL; a URL that does not open is a warning, never an error: a machine must
 * run whether or not anyone can watch it. */
static void lcm_open(struct lcm_status *s)
{
    if (!s->url[0])
        return;
    s->lcm = lcm_create(s->url);
    if (!s->lcm)
        fprintf(stderr, "lcm-status: warning: cannot open the LCM URL '%s'; the machine "
                "runs, but its status is not published. A udpm:// URL needs a multicast route "
                "(as root: `ip link set lo multicast on; ip route add 224.0.0.0/4 dev lo`); "
                "see docs/lcm.md.\n", s->url);
}

/* loadrt lcm-status: one instance, funct lcm-status.sample. */
static int lcm_status_load(struct hal *h, int argc, char **argv)
{
    long slots = LCM_RING_DEFAULT;
    int st = hal_args_check(h, LCM_STATUS_NAME, argc, argv, "url,rate,faults,ring");
    if (st != HAL_OK)
        return st;
    struct lcm_status *s = calloc(1, sizeof *s);
    if (!s)
        return hal_error(h, HAL_ERR_NOMEM, "loadrt lcm-status: out of memory");
    s->h = h;
    if ((st = hal_on_destroy(h, lcm_status_free, s)) != HAL_OK) {
        free(s);
        return st;
    }
    if ((st = lcm_config(h, s, argc, argv, &slots)) != HAL_OK)
        return st;
    if (ring_spsc_init(&s->samples, (size_t)slots, sizeof(struct lcm_sample)) != RING_OK ||
        ring_mpsc_init(&s->events, LCM_EVENTS_SLOTS, sizeof(struct lcm_event_slot)) != RING_OK)
        return hal_error(h, HAL_ERR_NOMEM, "loadrt lcm-status: out of memory for the rings");
    atomic_init(&s->sim, hal_sim_clock(h));
    if ((st = lcm_pins(h, s)) != HAL_OK ||
        (st = hal_set_object(h, LCM_STATUS_NAME, s)) != HAL_OK ||
        (st = hal_export_functf(h, lcm_sample_run, s, "%s.sample", LCM_STATUS_NAME)) != HAL_OK)
        return st;
    lcm_open(s);
    if (s->lcm && lcm_pub_start(s) != 0) {
        lcm_destroy(s->lcm);
        s->lcm = NULL;
        return hal_error(h, HAL_ERR_RT, "loadrt lcm-status: cannot start the publisher thread");
    }
    *s->active = s->lcm != NULL;
    return HAL_OK;
}

const struct hal_comp_type hal_comp_lcm_status = { LCM_STATUS_NAME, lcm_status_load };
