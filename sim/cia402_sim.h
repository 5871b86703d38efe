/* cia402_sim.h: a simulated CiA 402 servo drive on CANopen, for tests and configs/can-sim/. */
#ifndef HEXCNC_CIA402_SIM_H
#define HEXCNC_CIA402_SIM_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/drivers/canopen.h"
#include "hal/drivers/cia402.h"

/*
 * The drive side of the bus, pure (frames in, frames out, time passed in):
 *  - NMT slave: boot-up after power-on and after reset communication, Pre-operational,
 *    Operational, Stopped; heartbeat producer at the period written to 0x1017;
 *  - SDO server (expedited writes) for an object dictionary subset: 0x1017, 0x1400/0x1600,
 *    0x1800/0x1A00, 0x6040, 0x6041 (ro), 0x6060 (8 only), 0x6061 (ro), 0x6064 (ro), 0x607A,
 *    0x60C2; aborts with the CiA 301 codes (no object, read-only, bad value, not mappable);
 *  - synchronous PDOs: an RPDO is stored and actuated at the next SYNC; at each SYNC the
 *    TPDO is sent with the objects its mapping names (any mapping of the objects above);
 *  - the CiA 402 state machine driven by the controlword, and in Operation enabled a CSP
 *    position model: the actual position follows the target, velocity-limited; a quick stop
 *    as 0x605A says: codes 0..4 stop and then drop to Switch on disabled by themselves one
 *    SYNC later (power stage off), 5..8 stay in Quick stop active holding; default 2;
 *  - fault injection: drive fault with EMCY, heartbeat stop, TPDO stop, SDO abort, silence;
 *  - a start-up time: the boot-up message comes boot_delay_ns after power-on or reset.
 */

/* Faults to inject (a bit set). */
enum cia402_sim_fault {
    CIA402_SIM_DRIVE_FAULT = 1u << 0,    /* next SYNC: Fault reaction, EMCY, then Fault */
    CIA402_SIM_HEARTBEAT_STOP = 1u << 1, /* no more heartbeats; PDOs go on */
    CIA402_SIM_SDO_ABORT = 1u << 2,      /* abort writes to abort_index:abort_sub */
    CIA402_SIM_SDO_MUTE = 1u << 3,       /* SDO requests go unanswered */
    CIA402_SIM_SILENT = 1u << 4,         /* the node sends nothing at all (unplugged) */
    CIA402_SIM_TPDO_STOP = 1u << 5,      /* no more TPDOs (position feedback); heartbeats go on */
};

/* How one simulated drive is set up. */
struct cia402_sim_cfg {
    int node_id;                    /* 1..127 */
    double max_velocity_counts_s;   /* CSP following limit, counts/s; 0 = follows exactly */
    int32_t start_counts;           /* position actual value at power-on */
    int64_t boot_delay_ns;          /* boot-up sent this long after power-on or NMT reset
                                     * (a real drive's start-up takes 0.1..2 s), ns */
};

/* One simulated drive: its object dictionary, state machine, position and injected faults. */
struct cia402_sim {
    struct cia402_sim_cfg cfg;       /* as given */
    enum canopen_nmt_state nmt;      /* NMT state */
    bool boot_pending;               /* a boot-up message is due (at boot_due_ns) */
    int64_t boot_due_ns;             /* when it goes out; INT64_MIN: timed from the next call */
    int64_t next_heartbeat_ns;       /* when the next heartbeat is due */
    /* object dictionary (the SDO server reads and writes these through a table) */
    uint16_t heartbeat_ms;           /* 0x1017 */
    uint32_t rpdo_cob;               /* 0x1400:01 */
    uint8_t rpdo_tt;                 /* 0x1400:02 */
    uint8_t rpdo_count;              /* 0x1600:00 */
    uint32_t rpdo_map[4];            /* 0x1600:01..04 */
    uint32_t tpdo_cob;               /* 0x1800:01 */
    uint8_t tpdo_tt;                 /* 0x1800:02 */
    uint8_t tpdo_count;              /* 0x1A00:00 */
    uint32_t tpdo_map[4];            /* 0x1A00:01..04 */
    uint16_t controlword;            /* 0x6040 */
    uint16_t statusword;             /* 0x6041 */
    int16_t quick_stop_option;       /* 0x605A: 0..4 end in Switch on disabled, 5..8 hold */
    int8_t mode;                     /* 0x6060 */
    int8_t mode_display;             /* 0x6061 */
    int32_t actual_counts;           /* 0x6064 */
    int32_t target_counts;           /* 0x607A */
    uint8_t interp_value;            /* 0x60C2:01 */
    int8_t interp_index;             /* 0x60C2:02 */
    /* drive */
    enum cia402_state state;         /* device control state */
    uint16_t cw_applied;             /* controlword at the previous SYNC (for bit 7's edge) */
    bool rpdo_fresh;                 /* an RPDO arrived since the last SYNC */
    uint8_t rpdo_data[8];            /* its payload */
    uint8_t rpdo_len;                /* its length */
    /* fault injection */
    unsigned inject;                 /* enum cia402_sim_fault bits */
    uint16_t fault_code;             /* EMCY code sent with an injected drive fault */
    uint8_t fault_reg;               /* EMCY error register sent with it */
    uint16_t abort_index;            /* object whose writes are refused */
    uint8_t abort_sub;               /* its sub-index */
    uint32_t abort_code;             /* the abort code sent */
    /* counters */
    uint32_t syncs;                  /* SYNCs seen in Operational */
    uint32_t rpdos;                  /* RPDOs received */
    uint32_t sdo_writes;             /* SDO writes accepted */
};

/* Frames one rx or step can produce. */
#define CIA402_SIM_MAX_OUT 3

/* Powers the drive on: Not ready to switch on, boot-up due, dictionary at its defaults. */
void cia402_sim_init(struct cia402_sim *s, const struct cia402_sim_cfg *cfg);
/* Handles one frame from the bus at now_ns; returns the number of answers written to out. */
int cia402_sim_rx(struct cia402_sim *s, const struct can_frame *in, int64_t now_ns,
                  struct can_frame *out, int max_out);
/* Time-driven output (boot-up, heartbeat) at now_ns; returns the frames written to out. */
int cia402_sim_step(struct cia402_sim *s, int64_t now_ns, struct can_frame *out, int max_out);

/* Fault injection: set or clear bits; a drive fault uses code/reg for its EMCY. */
void cia402_sim_inject(struct cia402_sim *s, unsigned faults);
void cia402_sim_clear(struct cia402_sim *s, unsigned faults);
void cia402_sim_set_drive_fault(struct cia402_sim *s, uint16_t emcy_code, uint8_t error_reg);
void cia402_sim_set_abort(struct cia402_sim *s, uint16_t index, uint8_t sub, uint32_t code);

#endif
