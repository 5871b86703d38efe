/* lcm_status_priv.h: the lcm-status instance, shared by its HAL side and its publisher. */
#ifndef HEXCNC_LCM_STATUS_PRIV_H
#define HEXCNC_LCM_STATUS_PRIV_H

#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#include <lcm/lcm.h>

#include "hal/components/lcm_status.h"
#include "hal/hal.h"
#include "hal/ring.h"

#define LCM_STATUS_NAME "lcm-status"
#define LCM_AXES 6                  /* pose: X Y Z A B C */
#define LCM_LEGS 6
#define LCM_FAULTS_MAX 16           /* fault input pins */
#define LCM_FAULT_NAME_MAX 32
#define LCM_SOURCE_MAX 32
/* An event's text, bytes with the NUL: the runner's whole outcome (its 1024-byte error with
 * the cause of the stop, behind the status word) fits, so the cause is never cut off. */
#define LCM_TEXT_MAX 1280
#define LCM_URL_MAX 256
#define LCM_RING_DEFAULT 1024       /* samples: 50 s at 20 Hz, 1 s at 1 kHz */
#define LCM_EVENTS_SLOTS 256
/* Simulated clock: how often the publisher looks at the ring, real ns (machine time runs
 * far faster than real time, so it must not wait a whole publish period). */
#define LCM_SIM_POLL_NS 2000000L

/* What a ring slot holds. */
enum lcm_slot_kind {
    LCM_SLOT_SAMPLE = 1,            /* a status sample */
    LCM_SLOT_EDGE = 2,              /* fault inputs changed: becomes one event per bit */
};

/* One slot of the sample ring: a copy of the input pins at one servo period. */
struct lcm_sample {
    int32_t kind;                   /* enum lcm_slot_kind */
    int32_t state;                  /* motion state */
    int32_t line;                   /* program line */
    uint32_t faults;                /* fault inputs, bit i = input i */
    uint32_t changed;               /* EDGE: bits that changed since the previous period */
    int64_t t_ns;                   /* hal_now_ns(): machine time */
    int64_t mono_ns;                /* CLOCK_MONOTONIC (real time only), to date it */
    int32_t sim;                    /* taken on the simulated clock */
    int32_t pad;
    int64_t seq;                    /* sample number, 0, 1, 2, ... */
    double pose_cmd[LCM_AXES];      /* mm, deg */
    double pose_fb[LCM_AXES];       /* mm, deg */
    double leg_cmd[LCM_LEGS];       /* mm */
    double leg_fb[LCM_LEGS];        /* mm */
    double leg_rate[LCM_LEGS];      /* mm/s */
    double ferror[LCM_LEGS];        /* mm */
};

/* One slot of the event queue. */
struct lcm_event_slot {
    int64_t t_ns;                   /* machine time when posted */
    int64_t mono_ns;                /* CLOCK_MONOTONIC when posted (real time) */
    int32_t sim;                    /* posted on the simulated clock */
    int32_t severity, code, line;
    char source[LCM_SOURCE_MAX];
    char text[LCM_TEXT_MAX];
};

struct lcm_status {
    struct hal *h;
    /* input pins */
    double *pose_cmd[LCM_AXES], *pose_fb[LCM_AXES];          /* mm, deg */
    double *leg_cmd[LCM_LEGS], *leg_fb[LCM_LEGS];            /* mm */
    double *leg_rate[LCM_LEGS], *ferror[LCM_LEGS];           /* mm/s, mm */
    int32_t *state, *line;
    bool *fault[LCM_FAULTS_MAX];
    int nfaults;
    char fault_name[LCM_FAULTS_MAX][LCM_FAULT_NAME_MAX];
    /* output pins */
    uint32_t *sent;                 /* status messages published (wraps) */
    uint32_t *dropped;              /* samples dropped (wraps) */
    bool *active;                   /* true while publishing */

    /* servo side: touched only by lcm-status.sample (sim also read by the publisher) */
    _Atomic bool sim;               /* simulated clock: decimate by machine time */
    int64_t period_ns;              /* publish period, 1 / rate */
    int64_t next_due_ns;            /* simulated clock: machine time of the next sample */
    int64_t last_t_ns;              /* machine time of the previous call */
    _Atomic int64_t seq;            /* next sample number (only this funct writes it) */
    uint32_t last_faults;           /* fault inputs in the previous period */
    int32_t last_state;             /* state input in the previous period */
    _Atomic int32_t last_line;      /* line of the last call, for events posted with line < 0 */

    struct ring_spsc samples;       /* servo thread -> publisher */
    struct ring_mpsc events;        /* any thread -> publisher */

    /* publisher side */
    char url[LCM_URL_MAX];
    double rate_hz;
    lcm_t *lcm;                     /* NULL: not publishing */
    pthread_t thread;
    bool thread_started;
    _Atomic bool stop;              /* set at hal_destroy: drain, then leave */
    _Atomic uint64_t samples_done;  /* ring positions consumed and sent (or skipped) */
    _Atomic uint64_t events_done;   /* event positions consumed and sent */
    _Atomic uint64_t status_sent, events_sent, publish_errors;
};

/* lcm_status_pub.c: starts the publisher thread, and stops it after a last drain. */
int lcm_pub_start(struct lcm_status *s);
void lcm_pub_stop(struct lcm_status *s);
/* CLOCK_MONOTONIC in ns (vDSO: no system call). */
int64_t lcm_mono_ns(void);

#endif
