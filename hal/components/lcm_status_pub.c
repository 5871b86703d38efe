/* lcm_status_pub.c: the lcm-status publisher: a normal thread that drains the rings into LCM. */
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "hal/components/lcm_status_priv.h"
#include "lcmtypes/hexcnc_event_t.h"
#include "lcmtypes/hexcnc_status_t.h"

/* Longest sleep between looks at the stop flag, real ns: hal_destroy waits at most this. */
#define LCM_PUB_TICK_NS 10000000L

/* The clocks read once per drain, to turn machine time into wall-clock utime. */
struct lcm_clock {
    int64_t wall_us;                /* CLOCK_REALTIME, us */
    int64_t mono_ns;                /* CLOCK_MONOTONIC, ns, read at the same moment */
    int64_t last_t_ns;              /* machine time of the newest sample drained so far */
};

/* utime of a sample or event: machine time on the simulated clock (the same on every run),
 * else the wall-clock time at which it was taken. */
static int64_t lcm_utime(const struct lcm_clock *c, int32_t sim, int64_t t_ns, int64_t mono_ns)
{
    if (sim)
        return t_ns / 1000;
    return c->wall_us - (c->mono_ns - mono_ns) / 1000;
}

/* Counts a publish result; the first failure is reported once on stderr. */
static void lcm_pub_result(struct lcm_status *s, int rc, _Atomic uint64_t *sent)
{
    if (rc == 0) {
        atomic_fetch_add(sent, 1);
    } else if (atomic_fetch_add(&s->publish_errors, 1) == 0) {
        fprintf(stderr, "lcm-status: warning: publishing to '%s' failed (is the network or "
                "multicast route up? see docs/lcm.md); counting further failures silently\n",
                s->url);
    }
}

/* Names of the fault inputs set in `faults`, comma separated. */
static void lcm_fault_text(const struct lcm_status *s, uint32_t faults, char *buf, size_t len)
{
    size_t used = 0;
    buf[0] = '\0';
    for (int i = 0; i < s->nfaults && used < len; i++)
        if (faults & (1u << i)) {
            int n = snprintf(buf + used, len - used, "%s%s", used ? "," : "", s->fault_name[i]);
            used += n > 0 ? (size_t)n : 0;
        }
}

/* One hexcnc_status_t from a sample. */
static void lcm_pub_status(struct lcm_status *s, const struct lcm_sample *p,
                           const struct lcm_clock *c)
{
    char text[LCM_FAULTS_MAX * LCM_FAULT_NAME_MAX];
    hexcnc_status_t m;
    memset(&m, 0, sizeof m);
    m.utime = lcm_utime(c, p->sim, p->t_ns, p->mono_ns);
    m.machine_time_ns = p->t_ns;
    m.seq = p->seq;
    m.dropped = (int64_t)ring_spsc_dropped(&s->samples);
    m.state = p->state;
    m.line = p->line;
    memcpy(m.pose_cmd, p->pose_cmd, sizeof m.pose_cmd);
    memcpy(m.pose_fb, p->pose_fb, sizeof m.pose_fb);
    memcpy(m.leg_cmd_mm, p->leg_cmd, sizeof m.leg_cmd_mm);
    memcpy(m.leg_fb_mm, p->leg_fb, sizeof m.leg_fb_mm);
    memcpy(m.leg_rate_mm_s, p->leg_rate, sizeof m.leg_rate_mm_s);
    memcpy(m.ferror_mm, p->ferror, sizeof m.ferror_mm);
    m.fault_flags = (int32_t)p->faults;
    lcm_fault_text(s, p->faults, text, sizeof text);
    m.fault_text = text;
    lcm_pub_result(s, hexcnc_status_t_publish(s->lcm, LCM_STATUS_CHANNEL, &m), &s->status_sent);
}

/* One hexcnc_event_t. */
static void lcm_pub_event(struct lcm_status *s, const struct lcm_event_slot *e,
                          const struct lcm_clock *c)
{
    hexcnc_event_t m;
    memset(&m, 0, sizeof m);
    m.utime = lcm_utime(c, e->sim, e->t_ns, e->mono_ns);
    m.severity = (int8_t)e->severity;
    m.code = e->code;
    m.source = (char *)e->source;
    m.line = e->line;
    m.text = (char *)e->text;
    lcm_pub_result(s, hexcnc_event_t_publish(s->lcm, LCM_EVENT_CHANNEL, &m), &s->events_sent);
}

/* A change of fault inputs: one event per input that changed, raised before cleared. */
static void lcm_pub_edges(struct lcm_status *s, const struct lcm_sample *p,
                          const struct lcm_clock *c)
{
    for (int i = 0; i < s->nfaults; i++) {
        if (!(p->changed & (1u << i)))
            continue;
        bool raised = p->faults & (1u << i);
        struct lcm_event_slot e;
        memset(&e, 0, sizeof e);
        e.t_ns = p->t_ns;
        e.mono_ns = p->mono_ns;
        e.sim = p->sim;
        e.severity = raised ? LCM_SEV_FAULT : LCM_SEV_INFO;
        e.code = raised ? LCM_CODE_FAULT_RAISED : LCM_CODE_FAULT_CLEARED;
        e.line = p->line;
        snprintf(e.source, sizeof e.source, "%s", s->fault_name[i]);
        snprintf(e.text, sizeof e.text, raised ? "%s reports a fault (program line %d)"
                                               : "%s fault cleared (program line %d)",
                 s->fault_name[i], (int)p->line);
        lcm_pub_event(s, &e, c);
    }
}

/* Tells watchers once per drain that samples or events were lost since the last report. */
static void lcm_pub_losses(struct lcm_status *s, const struct lcm_clock *c,
                           uint64_t *seen_samples, uint64_t *seen_events)
{
    uint64_t ds = ring_spsc_dropped(&s->samples), de = ring_mpsc_dropped(&s->events);
    struct lcm_event_slot e;
    memset(&e, 0, sizeof e);
    e.mono_ns = c->mono_ns;
    e.t_ns = c->last_t_ns;
    e.sim = atomic_load(&s->sim);
    e.severity = LCM_SEV_WARNING;
    e.line = atomic_load(&s->last_line);
    snprintf(e.source, sizeof e.source, "%s", LCM_STATUS_NAME);
    if (ds > *seen_samples) {
        e.code = LCM_CODE_SAMPLES_DROPPED;
        snprintf(e.text, sizeof e.text, "%llu status samples lost: the publisher fell "
                 "behind (%llu in all)", (unsigned long long)(ds - *seen_samples),
                 (unsigned long long)ds);
        lcm_pub_event(s, &e, c);
        *seen_samples = ds;
    }
    if (de > *seen_events) {
        e.code = LCM_CODE_EVENTS_DROPPED;
        snprintf(e.text, sizeof e.text, "%llu events lost: the event queue was full (%llu "
                 "in all)", (unsigned long long)(de - *seen_events), (unsigned long long)de);
        lcm_pub_event(s, &e, c);
        *seen_events = de;
    }
}

/* The publisher's own state between looks at the rings. */
struct lcm_pub {
    struct lcm_clock c;
    struct lcm_sample newest;       /* real time: the newest sample not yet published */
    bool have;                      /* newest holds one */
    uint64_t seen_s, seen_e;        /* losses already reported */
};

/* Takes everything out of both rings. Simulated clock: every sample is sent (the servo side
 * has decimated by machine time). Real time: the newest sample is kept for the next publish
 * period (lcm_pub_newest); the ring is still emptied at every look, so a slow rate never
 * fills it. Fault edges and events are sent at once. */
static void lcm_pub_drain(struct lcm_status *s, struct lcm_pub *ps)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    ps->c.mono_ns = lcm_mono_ns();
    ps->c.wall_us = (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;

    const struct lcm_sample *p;
    while ((p = ring_spsc_peek(&s->samples))) {
        ps->c.last_t_ns = p->t_ns;
        if (p->kind == LCM_SLOT_EDGE) {
            lcm_pub_edges(s, p, &ps->c);
        } else if (p->sim) {
            lcm_pub_status(s, p, &ps->c);
        } else {
            ps->newest = *p;
            ps->have = true;
        }
        ring_spsc_release(&s->samples);
    }
    /* A kept sample is not done until it is published (lcm_status_flush waits for it). */
    atomic_store(&s->samples_done, ring_spsc_popped(&s->samples) - (ps->have ? 1 : 0));

    struct lcm_event_slot e;
    while (ring_mpsc_pop(&s->events, &e))
        lcm_pub_event(s, &e, &ps->c);
    lcm_pub_losses(s, &ps->c, &ps->seen_s, &ps->seen_e);
    atomic_store(&s->events_done, ring_mpsc_popped(&s->events));
}

/* Real time, once per publish period: the newest sample, if one came since the last. */
static void lcm_pub_newest(struct lcm_status *s, struct lcm_pub *ps)
{
    if (!ps->have)
        return;
    lcm_pub_status(s, &ps->newest, &ps->c);
    ps->have = false;
    atomic_store(&s->samples_done, ring_spsc_popped(&s->samples));
}

/* Sleeps until the absolute CLOCK_MONOTONIC time t_ns. */
static void lcm_sleep_until(int64_t t_ns)
{
    struct timespec ts = { (time_t)(t_ns / 1000000000), (long)(t_ns % 1000000000) };
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR) {
    }
}

/* The publisher thread: it empties the rings every LCM_PUB_TICK_NS at most (on the simulated
 * clock every LCM_SIM_POLL_NS) and, in real time, publishes the newest sample once per
 * publish period. After stop, one last drain and publish, so nothing taken is lost. */
static void *lcm_pub_main(void *arg)
{
    struct lcm_status *s = arg;
    struct lcm_pub ps;
    memset(&ps, 0, sizeof ps);
    int64_t next_pub = lcm_mono_ns() + s->period_ns;
    for (;;) {
        bool stop = atomic_load(&s->stop);
        bool sim = atomic_load(&s->sim);
        int64_t now = lcm_mono_ns();
        lcm_pub_drain(s, &ps);
        if (stop || now >= next_pub)
            lcm_pub_newest(s, &ps);
        if (stop)
            return NULL;
        if (now >= next_pub) {
            /* Keep the phase; after a long stall start again from now. */
            next_pub += s->period_ns;
            if (next_pub <= now)
                next_pub = now + s->period_ns;
        }
        int64_t wake = sim ? now + LCM_SIM_POLL_NS : next_pub;
        if (wake > now + LCM_PUB_TICK_NS)
            wake = now + LCM_PUB_TICK_NS;
        lcm_sleep_until(wake);
    }
}

/* Starts the publisher thread (normal priority: it must never compete with servo threads). */
int lcm_pub_start(struct lcm_status *s)
{
    atomic_store(&s->stop, false);
    if (pthread_create(&s->thread, NULL, lcm_pub_main, s) != 0)
        return -1;
    s->thread_started = true;
    return 0;
}

/* Asks the thread to drain once more and leave, and waits for it. */
void lcm_pub_stop(struct lcm_status *s)
{
    if (!s->thread_started)
        return;
    atomic_store(&s->stop, true);
    pthread_join(s->thread, NULL);
    s->thread_started = false;
}
