/* drive_startup.h: how a drive component tells the runner where its drives' start-up stands. */
#ifndef HEXCNC_DRIVE_STARTUP_H
#define HEXCNC_DRIVE_STARTUP_H

#include <stdatomic.h>
#include <stdint.h>

/*
 * A drive component (cia402, modbus) stores one of these as a HAL object under its name in
 * DRIVE_STARTUP_OBJECTS. The runner reads them while a started program has not moved yet:
 * it waits while some drive is starting (at most budget_ns, which the component derives from
 * its own configured time-outs), reports a failed start-up with the drive's own message, and
 * only when every drive is ready does a machine that stays idle mean an e-stop chain problem.
 */

enum drive_startup_state {
    DRIVE_STARTUP_STARTING = 0,   /* booting, being configured, first exchange not yet done */
    DRIVE_STARTUP_READY,          /* every drive answers and can be enabled */
    DRIVE_STARTUP_FAILED,         /* a drive faulted; its message went to the HAL queue */
};

struct drive_startup {
    _Atomic int state;            /* enum drive_startup_state, written by the servo thread */
    int64_t budget_ns;            /* the longest start-up the configuration allows, ns */
    const char *what;             /* for messages: "CAN drives (cia402)" */
};

#define DRIVE_STARTUP_OBJ_CIA402 "startup.cia402"
#define DRIVE_STARTUP_OBJ_MODBUS "startup.modbus"
/* Every name a drive component may use, for the runner to look up. */
#define DRIVE_STARTUP_OBJECTS { DRIVE_STARTUP_OBJ_CIA402, DRIVE_STARTUP_OBJ_MODBUS }

#endif
