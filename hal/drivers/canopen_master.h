/* canopen_master.h: a minimal CANopen master for CiA 402 drives in cyclic synchronous position. */
#ifndef HEXCNC_CANOPEN_MASTER_H
#define HEXCNC_CANOPEN_MASTER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "hal/drivers/canopen.h"
#include "hal/drivers/cia402.h"

/*
 * The pure core of the `cia402` HAL component: frames in (canopen_master_rx), frames out
 * (canopen_master_step), time passed in by the caller, no I/O, no blocking. Per node:
 *
 *   RESET --NMT reset communication--> WAIT_BOOT --boot-up--> CONFIG (expedited SDO writes:
 *   0x1017, 0x6060 = 8, 0x60C2, RPDO1/TPDO1 mapping) --NMT start--> RUN (SYNC, RPDO1 with
 *   controlword + target position, TPDO1 with statusword + position actual value; the CiA 402
 *   state machine is driven up to Operation enabled while `enable` is true).
 *
 * A communication fault (no boot-up, SDO abort or timeout, heartbeat or TPDO lost, boot-up
 * while running) puts the node into COMM_FAULT: no PDOs until a fault reset, which restarts
 * it from RESET. A drive fault (statusword Fault, EMCY, position out of range) leaves the node
 * in RUN; a fault reset sends the controlword's bit 7 edge and the state machine climbs back
 * to Operation enabled. Either way `fault` is latched with a message naming node and cause.
 */

#define CANOPEN_MASTER_MAX_NODES 16
#define CANOPEN_MSG_LEN 240
/* Frames one step can emit: a SYNC, one RPDO and one NMT or SDO request per node. */
#define CANOPEN_MASTER_MAX_TX(n) (1 + 2 * (n))
/* Missed SYNC cycles before lost feedback is a fault, by default (docs/can.md: at 2 ms SYNC
 * the 6 ms it allows plus the PDO delay stay inside the 10 ms in which a leg at full speed
 * would reach its following-error limit, and two late or lost frames are forgiven). */
#define CANOPEN_FEEDBACK_SYNCS_DEFAULT 3
#define CANOPEN_FEEDBACK_SYNCS_MAX 1000

/* Where the start-up of the whole bus stands (for the runner's wait before motion). */
enum canopen_startup {
    CANOPEN_STARTING = 0,   /* some node is still booting or being configured */
    CANOPEN_READY,          /* every node runs (Operational, its statusword received) */
    CANOPEN_FAILED,         /* some node has a fault latched (its message says why) */
};

/* One drive as the INI describes it. */
struct canopen_node_cfg {
    int node_id;            /* CANopen node-ID, 1..127 */
    int joint;              /* joint (leg) number, for messages */
    double counts_per_mm;   /* drive position counts per mm of leg length; sign = direction */
    double offset_mm;       /* leg length at drive position 0, mm */
    long sdo_timeout_ms;    /* answer to each configuration write expected within this, ms */
};

/* The bus as the INI describes it. */
struct canopen_master_cfg {
    int n_nodes;                 /* drives on the bus, 1..CANOPEN_MASTER_MAX_NODES */
    long sync_period_ns;         /* SYNC producer period = interpolation period 0x60C2, ns */
    long heartbeat_period_ms;    /* written to each node's 0x1017 (producer time), ms */
    long heartbeat_timeout_ms;   /* consumer: a node silent for longer is a fault, ms */
    long boot_timeout_ms;        /* boot-up expected this soon after reset communication, ms */
    int feedback_timeout_syncs;  /* a running node whose TPDO1 is missing for more than this
                                  * many SYNC periods is a fault; 0 = the default */
    struct canopen_node_cfg node[CANOPEN_MASTER_MAX_NODES];
};

/* Where the master is with one node. */
enum canopen_phase {
    CANOPEN_PHASE_RESET = 0, CANOPEN_PHASE_WAIT_BOOT, CANOPEN_PHASE_CONFIG, CANOPEN_PHASE_RUN,
    CANOPEN_PHASE_COMM_FAULT,
};

/* One node: inputs the caller sets, outputs it reads, and the protocol state. */
struct canopen_node {
    struct canopen_node_cfg cfg;   /* copied from the configuration */
    /* inputs, set before each step */
    double position_cmd_mm;        /* commanded leg length, mm */
    bool enable;                   /* drive to Operation enabled while true */
    bool fault_reset;              /* rising edge: reset the latched fault */
    bool quick_stop;               /* while true, an enabled drive gets quick stop (0x02):
                                    * it brakes on its own ramp and holds (Quick stop active) */
    /* outputs */
    double position_fb_mm;         /* leg length from position actual value 0x6064, mm */
    bool fb_valid;                 /* a position actual value has ever been received */
    bool fault;                    /* a latched fault; `message` says which */
    int fault_status;              /* enum canopen_status of the latched fault */
    enum cia402_state state;       /* decoded from the last statusword */
    uint16_t statusword;           /* last 0x6041 received */
    uint16_t emcy_code;            /* last EMCY error code (0 after an error reset) */
    uint8_t emcy_reg;              /* last EMCY error register */
    char message[CANOPEN_MSG_LEN]; /* the last fault message, machinist's words */
    bool message_new;              /* set when `message` changes; the shell clears it */
    /* protocol state */
    enum canopen_phase phase;      /* see above */
    int64_t deadline_ns;           /* boot-up or SDO answer due by then */
    int sdo_step;                  /* index into the configuration writes */
    bool sdo_pending;              /* a write is out, its answer not yet in */
    bool heartbeat_seen;           /* monitoring starts with the first heartbeat (CiA 301) */
    int64_t last_heartbeat_ns;     /* when the last heartbeat arrived */
    int64_t last_tpdo_ns;          /* when the last TPDO1 arrived (or RUN began) */
    bool actual_valid;             /* a TPDO1 has been received since RUN began */
    int32_t actual_counts;         /* last position actual value */
    uint16_t controlword;          /* last controlword sent */
    bool reset_prev;               /* fault_reset input last step, for the edge */
    int reset_stage;               /* 0 none, 1 bit 7 low, 2 bit 7 high until Fault is left */
};

/* The master: configuration, nodes, SYNC timing and counters. */
struct canopen_master {
    struct canopen_master_cfg cfg;                  /* as given to init */
    struct canopen_node node[CANOPEN_MASTER_MAX_NODES];
    uint8_t slot[CANOPEN_NODE_MAX + 1];             /* node-ID -> index + 1, 0 = not ours */
    uint8_t interp_value;                           /* 0x60C2:01 */
    int8_t interp_index;                            /* 0x60C2:02 (power of ten, seconds) */
    int64_t next_sync_ns;                           /* when the next SYNC is due */
    uint32_t sync_count;                            /* SYNCs sent */
    uint32_t rx_frames;                             /* frames handed to rx */
    uint32_t rx_ignored;                            /* of which not for this master */
    uint32_t tx_overflow;                           /* frames dropped: output buffer full */
};

/* Checks the configuration and resets every node to RESET; CANOPEN_ERR_ARG with a message
 * in err (naming the node) when a value is unusable. */
int canopen_master_init(struct canopen_master *m, const struct canopen_master_cfg *cfg,
                        char *err, size_t errlen);
/* Consumes one received frame at time now_ns. */
void canopen_master_rx(struct canopen_master *m, const struct can_frame *f, int64_t now_ns);
/* Advances every node to now_ns; writes the frames to send (at most
 * CANOPEN_MASTER_MAX_TX(n_nodes)) into out and returns their number. */
int canopen_master_step(struct canopen_master *m, int64_t now_ns, struct can_frame *out,
                        int max_out);
/* True when every node is in RUN and Operation enabled. */
bool canopen_master_all_enabled(const struct canopen_master *m);
/* The transport is gone: every node gets a communication fault with `why` as its message
 * (message_new stays false: the caller reports the bus once, not each node). */
void canopen_master_bus_lost(struct canopen_master *m, const char *why);
/* The bus's start-up: starting, ready or failed (then *failed_node = its index, else -1). */
enum canopen_startup canopen_master_startup(const struct canopen_master *m, int *failed_node);
/* The longest start-up the configuration allows, ns: BOOT_TIMEOUT, every configuration write
 * at its SDO_TIMEOUT, and the CiA 402 climb (a few SYNC periods); step_ns = servo period. */
int64_t canopen_master_startup_budget_ns(const struct canopen_master *m, long step_ns);
/* The node with this node-ID, or NULL. */
struct canopen_node *canopen_master_node(struct canopen_master *m, int node_id);

/* Drive position counts <-> leg length in mm for one node. */
double canopen_counts_to_mm(const struct canopen_node_cfg *c, int32_t counts);
/* false when the length maps outside the 32-bit range of 0x607A. */
bool canopen_mm_to_counts(const struct canopen_node_cfg *c, double mm, int32_t *counts);
/* Packs / unpacks the 6-byte PDOs of the fixed mapping (u16 word, then i32 position, LE). */
void canopen_pdo_pack(struct can_frame *f, uint32_t cob, uint16_t word, int32_t position);
bool canopen_pdo_unpack(const struct can_frame *f, uint16_t *word, int32_t *position);

#endif
