/* lcm_status.h: the `lcm-status` HAL component: machine status and events published over LCM. */
#ifndef HEXCNC_LCM_STATUS_H
#define HEXCNC_LCM_STATUS_H

#include <stdint.h>

#include <lcm/lcm.h>

#include "hal/hal.h"

/*
 * `loadrt lcm-status [url=URL] [rate=HZ] [faults=NAME,NAME,...] [ring=SLOTS]` (URL and rate
 * default to [LCM] URL and [LCM] RATE_HZ of the INI; no URL = not published). The servo
 * thread calls `lcm-status.sample`, which copies the input pins into a lock-free ring; a
 * normal-priority thread publishes them as hexcnc_status_t on HEXCNC_STATUS, and events as
 * hexcnc_event_t on HEXCNC_EVENT. See docs/lcm.md.
 */

#define LCM_STATUS_CHANNEL "HEXCNC_STATUS"
#define LCM_EVENT_CHANNEL "HEXCNC_EVENT"

enum lcm_status_status {
    LCM_STATUS_OK = 0,
    LCM_STATUS_NOT_LOADED,     /* no lcm-status component in this HAL runtime */
    LCM_STATUS_DISABLED,       /* loaded, but not publishing (no URL, or it did not open) */
    LCM_STATUS_FULL,           /* the event queue was full: the event was dropped (counted) */
    LCM_STATUS_TIMEOUT,        /* lcm_status_flush: the publisher did not catch up in time */
    LCM_STATUS_STATUS_COUNT
};
const char *lcm_status_strerror(int status);

/* Event severities, the values of hexcnc_event_t's INFO / WARNING / FAULT. */
enum lcm_status_severity {
    LCM_SEV_INFO = 0,
    LCM_SEV_WARNING = 1,
    LCM_SEV_FAULT = 2,
};

/* Event codes the component itself posts; other posters use codes from 100 up. */
enum lcm_status_code {
    LCM_CODE_FAULT_RAISED = 1,     /* a fault input went true (source: its name) */
    LCM_CODE_FAULT_CLEARED = 2,    /* a fault input went false again */
    LCM_CODE_SAMPLES_DROPPED = 3,  /* status samples were lost (the publisher fell behind) */
    LCM_CODE_EVENTS_DROPPED = 4,   /* events were lost (the event queue was full) */
    LCM_CODE_USER = 100,           /* first code for other components and the runner */
};

/* Posts an event: copied into a lock-free queue (no lock, no allocation, no system call), so
 * any thread may call it, a servo-thread function included; the publisher sends it on
 * HEXCNC_EVENT. source and text are cut to 31 and 1279 characters. line < 0 means "the
 * program line the last sample saw". Returns LCM_STATUS_OK, or NOT_LOADED / DISABLED
 * (nothing to do: callers may ignore them) or FULL. */
int lcm_status_post_event(struct hal *h, enum lcm_status_severity severity, int32_t code,
                          const char *source, int32_t line, const char *fmt, ...)
    __attribute__((format(printf, 6, 7)));

/* What the component has done so far. */
struct lcm_status_stats {
    uint64_t samples;           /* status samples taken by lcm-status.sample, dropped ones too */
    uint64_t samples_dropped;   /* ring slots lost because the ring was full */
    uint64_t status_sent;       /* hexcnc_status_t messages published */
    uint64_t events_sent;       /* hexcnc_event_t messages published */
    uint64_t events_dropped;    /* events lost: the event queue was full */
    uint64_t publish_errors;    /* lcm_publish failures */
};
int lcm_status_get_stats(struct hal *h, struct lcm_status_stats *st);

/* Waits (sleeping, off the servo path) until everything pushed before the call has been
 * published, at most timeout_ms. The runner calls it before exit; tests before reading. */
int lcm_status_flush(struct hal *h, int timeout_ms);

/* The component's LCM instance, or NULL when not publishing. For memq:// (in-process only)
 * a test subscribes on it and calls lcm_handle_timeout; nothing else should use it. */
lcm_t *lcm_status_lcm(struct hal *h);

#endif
