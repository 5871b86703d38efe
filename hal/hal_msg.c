/* hal_msg.c: messages from components (any thread) to the shell, through a lock-free queue. */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "hal/hal_priv.h"

/* Messages that may wait for the shell; a burst beyond this is dropped and counted. */
#define HAL_MSG_SLOTS 64

int hal_msg_init(struct hal *h)
{
    return ring_mpsc_init(&h->msgs, HAL_MSG_SLOTS, sizeof(struct hal_msg)) == RING_OK
               ? HAL_OK : HAL_ERR_NOMEM;
}

void hal_msg_free(struct hal *h)
{
    ring_mpsc_free(&h->msgs);
}

/* Formats on the caller's stack (vsnprintf of short texts neither locks nor allocates),
 * then copies the message into a free slot. */
int hal_msg_post(struct hal *h, enum hal_msg_severity sev, const char *source,
                 const char *fmt, ...)
{
    struct hal_msg m;
    m.severity = sev;
    snprintf(m.source, sizeof m.source, "%s", source ? source : "");
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(m.text, sizeof m.text, fmt, ap);
    va_end(ap);
    return ring_mpsc_push(&h->msgs, &m) ? HAL_OK : HAL_ERR_NOMEM;
}

bool hal_msg_take(struct hal *h, struct hal_msg *out)
{
    return ring_mpsc_pop(&h->msgs, out);
}

uint64_t hal_msg_dropped(const struct hal *h)
{
    return ring_mpsc_dropped(&h->msgs);
}

const char *hal_msg_severity_name(enum hal_msg_severity sev)
{
    switch (sev) {
    case HAL_MSG_INFO: return "info";
    case HAL_MSG_WARNING: return "warning";
    case HAL_MSG_FAULT: return "fault";
    }
    return "?";
}
