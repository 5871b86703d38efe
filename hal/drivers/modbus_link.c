/* modbus_link.c: the mailbox, fault latch and I/O thread that decouple a Modbus drive from the servo thread. */
#include "hal/drivers/modbus_link.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

/* Monotonic time, ns. */
static int64_t modbus_link_now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

/* Prepares the drive; the connection is made by the first cycle. */
int modbus_link_init(struct modbus_link *l, const struct modbus_drive_cfg *cfg)
{
    memset(l, 0, sizeof(*l));
    return modbus_drive_open(&l->drive, cfg);
}

/* Ends the thread and frees the drive. */
void modbus_link_fini(struct modbus_link *l)
{
    modbus_link_stop(l);
    modbus_drive_close(&l->drive);
}

/* The servo side's command: position and enable, each one atomic store. */
void modbus_link_command(struct modbus_link *l, double pos_mm, bool enable)
{
    uint64_t bits;
    memcpy(&bits, &pos_mm, sizeof(bits));
    atomic_store_explicit(&l->cmd_pos_bits, bits, memory_order_relaxed);
    atomic_store_explicit(&l->cmd_enable, enable ? 1u : 0u, memory_order_relaxed);
    atomic_store_explicit(&l->cmd_posted, 1u, memory_order_release);
}

/* The servo side asks to clear the fault and reconnect. */
void modbus_link_reset(struct modbus_link *l)
{
    atomic_fetch_add_explicit(&l->reset_req, 1u, memory_order_release);
}

/* The servo side's view of the drive. */
void modbus_link_feedback(struct modbus_link *l, struct modbus_feedback *fb)
{
    uint64_t w = atomic_load_explicit(&l->fb_word, memory_order_acquire);
    fb->pos_mm = modbus_counts_to_mm((int32_t)(uint32_t)(w & 0xffffffffu),
                                     l->drive.cfg.counts_per_mm);
    fb->status_word = (uint16_t)(w >> 32);
    /* A reset not yet taken by the I/O side hides the old fault, so an e-stop chain can be
     * reset in the same period; a retry that fails raises it again. */
    bool pending = atomic_load_explicit(&l->reset_req, memory_order_relaxed) !=
                   atomic_load_explicit(&l->reset_ack, memory_order_acquire);
    fb->fault = !pending && atomic_load_explicit(&l->fault, memory_order_acquire) != 0;
    fb->fault_seq = atomic_load_explicit(&l->fault_seq, memory_order_acquire);
    fb->connected = atomic_load_explicit(&l->connected, memory_order_relaxed) != 0;
    fb->rtt_us = atomic_load_explicit(&l->rtt_ns, memory_order_relaxed) / 1000.0;
    fb->rtt_max_us = atomic_load_explicit(&l->rtt_max_ns, memory_order_relaxed) / 1000.0;
    fb->errors = atomic_load_explicit(&l->errors, memory_order_relaxed);
    fb->exchanges = atomic_load_explicit(&l->exchanges, memory_order_relaxed);
}

/* The message of the latched fault. */
const char *modbus_link_fault_message(const struct modbus_link *l)
{
    return l->fault_msg;
}

/* Latches a fault: message first, then the flag (release), then the report. */
static int modbus_link_raise(struct modbus_link *l, int status, const char *msg)
{
    snprintf(l->fault_msg, sizeof(l->fault_msg), "%s", msg);
    atomic_fetch_add_explicit(&l->errors, 1u, memory_order_relaxed);
    atomic_store_explicit(&l->connected, l->drive.connected ? 1u : 0u, memory_order_relaxed);
    atomic_store_explicit(&l->fault, 1u, memory_order_release);
    atomic_fetch_add_explicit(&l->fault_seq, 1u, memory_order_release);
    if (l->report)
        l->report(l->report_arg, l->fault_msg);
    return status;
}

/* A reset from the servo side: unlatch, start from a fresh connection. */
static void modbus_link_take_reset(struct modbus_link *l)
{
    uint32_t req = atomic_load_explicit(&l->reset_req, memory_order_acquire);
    if (req == atomic_load_explicit(&l->reset_ack, memory_order_relaxed))
        return;
    if (atomic_load_explicit(&l->fault, memory_order_relaxed)) {
        modbus_drive_disconnect(&l->drive);
        atomic_store_explicit(&l->connected, 0u, memory_order_relaxed);
        l->send_fault_reset = true;
        atomic_store_explicit(&l->fault, 0u, memory_order_release);
    }
    atomic_store_explicit(&l->reset_ack, req, memory_order_release);
}

/* Publishes a good exchange's results and round trip. */
static void modbus_link_publish(struct modbus_link *l, int32_t actual, uint16_t status,
                                int64_t rtt_ns)
{
    uint64_t w = (uint64_t)(uint32_t)actual | ((uint64_t)status << 32);
    atomic_store_explicit(&l->fb_word, w, memory_order_release);
    uint32_t rtt = rtt_ns > (int64_t)UINT32_MAX ? UINT32_MAX : (uint32_t)rtt_ns;
    atomic_store_explicit(&l->rtt_ns, rtt, memory_order_relaxed);
    if (rtt > atomic_load_explicit(&l->rtt_max_ns, memory_order_relaxed))
        atomic_store_explicit(&l->rtt_max_ns, rtt, memory_order_relaxed);
    atomic_fetch_add_explicit(&l->exchanges, 1u, memory_order_relaxed);
}

/* The servo side's command as target counts and control word; a range error latches. */
static int modbus_link_take_command(struct modbus_link *l, int32_t *target, uint16_t *control)
{
    struct modbus_drive *d = &l->drive;
    uint64_t bits = atomic_load_explicit(&l->cmd_pos_bits, memory_order_relaxed);
    double pos_mm;
    memcpy(&pos_mm, &bits, sizeof(pos_mm));
    if (modbus_mm_to_counts(pos_mm, d->cfg.counts_per_mm, target)) {
        char msg[320];
        snprintf(msg, sizeof(msg), "modbus drive %d (%s): position command %.3f mm is beyond "
                 "the drive's 32-bit count range at %g counts/mm", d->cfg.index, d->where,
                 pos_mm, d->cfg.counts_per_mm);
        return modbus_link_raise(l, MODBUS_DRIVE_ERR_RANGE, msg);
    }
    *control = atomic_load_explicit(&l->cmd_enable, memory_order_relaxed) ? MODBUS_CTRL_ENABLE : 0;
    if (l->send_fault_reset)
        *control |= MODBUS_CTRL_FAULT_RESET;
    return MODBUS_DRIVE_OK;
}

/* One set-point cycle (see modbus_link.h). */
int modbus_link_cycle(struct modbus_link *l)
{
    struct modbus_drive *d = &l->drive;
    modbus_link_take_reset(l);
    if (atomic_load_explicit(&l->fault, memory_order_relaxed))
        return MODBUS_DRIVE_OK;
    if (!d->connected) {
        int rc = modbus_drive_connect(d);
        if (rc)
            return modbus_link_raise(l, rc, modbus_drive_message(d));
        atomic_store_explicit(&l->connected, 1u, memory_order_relaxed);
    }
    /* Before the first command only read, so the feedback is the drive's own position. */
    bool posted = atomic_load_explicit(&l->cmd_posted, memory_order_acquire) != 0;
    int32_t target = 0, actual;
    uint16_t control = 0, status;
    int rc;
    if (posted && (rc = modbus_link_take_command(l, &target, &control)))
        return rc;
    bool resetting = (control & MODBUS_CTRL_FAULT_RESET) != 0;
    int64_t t0 = modbus_link_now_ns();
    rc = posted ? modbus_drive_exchange(d, target, control, &actual, &status)
                : modbus_drive_read(d, &actual, &status);
    int64_t t1 = modbus_link_now_ns();
    if (rc)
        return modbus_link_raise(l, rc, modbus_drive_message(d));
    if (resetting)
        l->send_fault_reset = false;
    modbus_link_publish(l, actual, status, t1 - t0);
    /* A drive gets the one exchange that carries FAULT_RESET to clear its fault bit. */
    if ((status & MODBUS_STAT_FAULT) && !resetting) {
        char msg[320];
        snprintf(msg, sizeof(msg), "modbus drive %d (%s): drive reports a fault (status word "
                 "0x%04x)", d->cfg.index, d->where, (unsigned)status);
        return modbus_link_raise(l, MODBUS_DRIVE_ERR_FAULT, msg);
    }
    return MODBUS_DRIVE_OK;
}

/* The I/O thread: a cycle per set-point period on absolute deadlines; an overrun (a slow
 * answer) moves the next deadline forward instead of firing a burst of catch-up cycles. */
static void *modbus_link_thread(void *arg)
{
    struct modbus_link *l = arg;
    long period_ns = l->drive.cfg.period_ns;
    struct timespec next;
    clock_gettime(CLOCK_MONOTONIC, &next);
    while (!atomic_load_explicit(&l->stop, memory_order_acquire)) {
        modbus_link_cycle(l);
        next.tv_nsec += period_ns;
        while (next.tv_nsec >= 1000000000) {
            next.tv_nsec -= 1000000000;
            next.tv_sec++;
        }
        struct timespec now;
        clock_gettime(CLOCK_MONOTONIC, &now);
        if (now.tv_sec > next.tv_sec || (now.tv_sec == next.tv_sec && now.tv_nsec > next.tv_nsec))
            next = now;
        while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, NULL) == EINTR)
            ;
    }
    return NULL;
}

/* Starts the I/O thread. */
int modbus_link_start(struct modbus_link *l)
{
    if (l->thread_started)
        return MODBUS_DRIVE_OK;
    atomic_store(&l->stop, false);
    if (pthread_create(&l->thread, NULL, modbus_link_thread, l))
        return MODBUS_DRIVE_ERR_THREAD;
    l->thread_started = true;
    return MODBUS_DRIVE_OK;
}

/* Stops and joins the I/O thread. */
void modbus_link_stop(struct modbus_link *l)
{
    if (!l->thread_started)
        return;
    atomic_store_explicit(&l->stop, true, memory_order_release);
    pthread_join(l->thread, NULL);
    l->thread_started = false;
}
