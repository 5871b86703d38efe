/* cia402_hal.c: HAL component `cia402`: the CANopen master core on a non-blocking CAN socket. */
#include "hal/drivers/cia402_hal.h"

#include <stdlib.h>
#include <string.h>

#include "hal/drivers/can_bus.h"
#include "hal/drivers/can_load.h"
#include "hal/drivers/canopen_master.h"
#include "hal/drivers/drive_startup.h"

#define CIA402_RX_MAX 256   /* frames read per period at most; more wait for the next one */

/* The pins of one drive. */
struct cia402_chan {
    double *pos_cmd;        /* in: commanded leg length, mm */
    double *pos_fb;         /* out: leg length from position actual value, mm */
    bool *enable;           /* in: drive to Operation enabled */
    bool *fault;            /* out: latched fault */
    bool *fault_reset;      /* in: rising edge resets the fault */
    bool *quick_stop;       /* in: quick stop an enabled drive while true */
    int32_t *state;         /* out: enum cia402_state */
    uint32_t *statusword;   /* out: 0x6041 */
    uint32_t *emcy_code;    /* out: last EMCY error code */
};

/* The component: bus, master core, simulated time and pins. */
struct cia402_comp {
    struct hal *h;                          /* for messages to the shell (hal_msg_post) */
    struct can_bus bus;                     /* the socket (and the sim's end) */
    struct canopen_master m;                /* the protocol core */
    struct drive_startup startup;           /* for the runner: starting / ready / failed */
    int64_t now_ns;                         /* sum of the periods this funct has run */
    struct cia402_chan chan[CANOPEN_MASTER_MAX_NODES];
    bool *fault_any;                        /* out: any drive faulted or bus-off */
    bool *all_enabled;                      /* out: all drives in Operation enabled */
    bool *bus_error;                        /* out: trouble on the bus this period */
    bool *bus_off;                          /* out: controller bus-off */
    uint32_t *tx_dropped, *rx_errors, *err_frames, *sync_count;  /* out: counters */
    struct can_frame rx[CIA402_RX_MAX];     /* receive buffer */
    struct can_frame tx[CANOPEN_MASTER_MAX_TX(CANOPEN_MASTER_MAX_NODES)];  /* send buffer */
};

/* One servo period: read what arrived, run the nodes, send SYNC/RPDOs/requests. */
static void cia402_update(void *arg, long period_ns)
{
    struct cia402_comp *c = arg;
    struct canopen_master *m = &c->m;
    uint32_t dropped = c->bus.tx_dropped, rxerr = c->bus.rx_errors;
    bool closed_before = c->bus.peer_closed;
    int nrx = can_bus_recv_batch(&c->bus, c->rx, CIA402_RX_MAX);
    for (int i = 0; i < nrx; i++)
        canopen_master_rx(m, &c->rx[i], c->now_ns);
    bool any = c->bus.bus_off || c->bus.peer_closed;
    for (int i = 0; i < m->cfg.n_nodes; i++) {
        struct canopen_node *n = &m->node[i];
        struct cia402_chan *ch = &c->chan[i];
        n->position_cmd_mm = *ch->pos_cmd;
        n->enable = *ch->enable;
        n->fault_reset = *ch->fault_reset;
        n->quick_stop = *ch->quick_stop;
    }
    int ntx = canopen_master_step(m, c->now_ns, c->tx, (int)(sizeof c->tx / sizeof c->tx[0]));
    can_bus_send_batch(&c->bus, c->tx, ntx);
    if (c->bus.peer_closed && !closed_before) {  /* once: every drive is gone with it */
        char why[CANOPEN_MSG_LEN];
        snprintf(why, sizeof why, "CAN bus %s: the other end closed the connection (%s): "
                 "every drive is off the bus", c->bus.ifname, strerror(c->bus.last_errno));
        canopen_master_bus_lost(m, why);
        hal_msg_post(c->h, HAL_MSG_FAULT, "cia402", "%s", why);
    }
    for (int i = 0; i < m->cfg.n_nodes; i++) {
        struct canopen_node *n = &m->node[i];
        struct cia402_chan *ch = &c->chan[i];
        /* Until the drive has reported once, echo the command (as a stepgen powers up at
         * it): the forward kinematics then sees legs, not zeros. */
        *ch->pos_fb = n->fb_valid ? n->position_fb_mm : *ch->pos_cmd;
        *ch->fault = n->fault;
        *ch->state = (int32_t)n->state;
        *ch->statusword = n->statusword;
        *ch->emcy_code = n->emcy_code;
        any = any || n->fault;
        if (n->message_new) {  /* once per fault: the machinist's message, without blocking */
            char src[32];
            snprintf(src, sizeof src, "cia402.%d", i);
            hal_msg_post(c->h, n->fault ? HAL_MSG_FAULT : HAL_MSG_INFO, src, "%s", n->message);
            n->message_new = false;
        }
    }
    *c->fault_any = any;
    *c->all_enabled = canopen_master_all_enabled(m);
    *c->bus_off = c->bus.bus_off;
    *c->bus_error = c->bus.bus_off || c->bus.peer_closed || c->bus.tx_dropped != dropped || c->bus.rx_errors != rxerr;
    *c->tx_dropped = c->bus.tx_dropped;
    *c->rx_errors = c->bus.rx_errors;
    *c->err_frames = c->bus.err_frames;
    *c->sync_count = m->sync_count;
    int failed;
    static const int startup_of[] = { [CANOPEN_STARTING] = DRIVE_STARTUP_STARTING,
                                      [CANOPEN_READY] = DRIVE_STARTUP_READY,
                                      [CANOPEN_FAILED] = DRIVE_STARTUP_FAILED };
    enum canopen_startup su = canopen_master_startup(m, &failed);
    atomic_store(&c->startup.state, c->bus.bus_off || c->bus.peer_closed ? DRIVE_STARTUP_FAILED : startup_of[su]);
    c->now_ns += period_ns;
}

/* [section]key as a whole number: def when absent and optional, an error when required. */
static int ini_long(struct hal *h, const char *sec, const char *key, long def, bool required,
                    long *out)
{
    int st = hal_ini_int(h, sec, key, def, out);
    if (st == HAL_ERR_NOT_FOUND && !required)
        return HAL_OK;
    return st;
}

/* The same for a floating-point value. */
static int ini_double(struct hal *h, const char *sec, const char *key, double def,
                      bool required, double *out)
{
    int st = hal_ini_double(h, sec, key, def, out);
    if (st == HAL_ERR_NOT_FOUND && !required)
        return HAL_OK;
    return st;
}

/* [CAN_NODE_i]: NODE_ID and COUNTS_PER_MM required, OFFSET (mm), SDO_TIMEOUT (ms). */
static int read_node(struct hal *h, int i, struct canopen_node_cfg *nc)
{
    char sec[32];
    long id, sdo;
    snprintf(sec, sizeof sec, "CAN_NODE_%d", i);
    int st = ini_long(h, sec, "NODE_ID", 0, true, &id);
    st = st ? st : ini_double(h, sec, "COUNTS_PER_MM", 0, true, &nc->counts_per_mm);
    st = st ? st : ini_double(h, sec, "OFFSET", 0, false, &nc->offset_mm);
    st = st ? st : ini_long(h, sec, "SDO_TIMEOUT", 100, false, &sdo);
    nc->node_id = (int)id;
    nc->joint = i;
    nc->sdo_timeout_ms = sdo;
    return st;
}

/* [CAN] and every [CAN_NODE_i] into a master configuration. */
static int read_cfg(struct hal *h, int count, struct canopen_master_cfg *cfg, long *bitrate,
                    long *servo_out_ns)
{
    long servo_ns, fb_syncs = CANOPEN_FEEDBACK_SYNCS_DEFAULT;
    memset(cfg, 0, sizeof *cfg);
    cfg->n_nodes = count;
    int st = ini_long(h, "EMCMOT", "SERVO_PERIOD", 1000000, false, &servo_ns);
    st = st ? st : ini_long(h, "CAN", "SYNC_PERIOD", servo_ns, false, &cfg->sync_period_ns);
    st = st ? st : ini_long(h, "CAN", "BITRATE", 1000000, false, bitrate);
    st = st ? st : ini_long(h, "CAN", "HEARTBEAT_PERIOD", 20, false, &cfg->heartbeat_period_ms);
    st = st ? st : ini_long(h, "CAN", "HEARTBEAT_TIMEOUT", 100, false,
                            &cfg->heartbeat_timeout_ms);
    st = st ? st : ini_long(h, "CAN", "BOOT_TIMEOUT", 1000, false, &cfg->boot_timeout_ms);
    st = st ? st : ini_long(h, "CAN", "FEEDBACK_TIMEOUT_SYNCS", CANOPEN_FEEDBACK_SYNCS_DEFAULT,
                            false, &fb_syncs);
    if (!st && (fb_syncs < 1 || fb_syncs > CANOPEN_FEEDBACK_SYNCS_MAX))
        return hal_error(h, HAL_ERR_COMPONENT, "cia402: %s: [CAN]FEEDBACK_TIMEOUT_SYNCS = %ld: "
                         "1 to %d SYNC periods", hal_ini_path(h), fb_syncs,
                         CANOPEN_FEEDBACK_SYNCS_MAX);
    cfg->feedback_timeout_syncs = (int)fb_syncs;
    *servo_out_ns = servo_ns;
    for (int i = 0; i < count && !st; i++)
        st = read_node(h, i, &cfg->node[i]);
    if (!st && servo_ns > 0 && cfg->sync_period_ns % servo_ns != 0)
        return hal_error(h, HAL_ERR_COMPONENT, "cia402: %s: [CAN]SYNC_PERIOD %ld ns is not a "
                         "multiple of [EMCMOT]SERVO_PERIOD %ld ns: SYNCs would jitter",
                         hal_ini_path(h), cfg->sync_period_ns, servo_ns);
    return st;
}

/* Refuses a configuration the bus cannot carry; warns above 80 % (docs/can.md). */
static int check_bus_load(struct hal *h, const struct canopen_master_cfg *cfg, long bitrate)
{
    double load = can_csp_load(cfg->n_nodes, 6, 6, 1e9 / (double)cfg->sync_period_ns,
                               1e3 / (double)cfg->heartbeat_period_ms, (double)bitrate);
    if (load > 1.0)
        return hal_error(h, HAL_ERR_COMPONENT, "cia402: %s: %d drives with [CAN]SYNC_PERIOD "
                         "%ld ns need %.0f %% of the %ld bit/s bus (worst-case stuffing): "
                         "raise SYNC_PERIOD (docs/can.md has the table)", hal_ini_path(h),
                         cfg->n_nodes, cfg->sync_period_ns, 100.0 * load, bitrate);
    if (load > 0.8)
        fprintf(stderr, "cia402: warning: the CAN bus will be %.0f %% busy; frames of other "
                "devices may be delayed\n", 100.0 * load);
    return HAL_OK;
}

/* The pins of drive i. */
static int chan_new(struct hal *h, struct cia402_chan *ch, int i)
{
    int st = hal_pin_float_newf(h, HAL_IN, &ch->pos_cmd, "cia402.%d.position-cmd", i);
    st = st ? st : hal_pin_float_newf(h, HAL_OUT, &ch->pos_fb, "cia402.%d.position-fb", i);
    st = st ? st : hal_pin_bit_newf(h, HAL_IN, &ch->enable, "cia402.%d.enable", i);
    st = st ? st : hal_pin_bit_newf(h, HAL_OUT, &ch->fault, "cia402.%d.fault", i);
    st = st ? st : hal_pin_bit_newf(h, HAL_IN, &ch->fault_reset, "cia402.%d.fault-reset", i);
    st = st ? st : hal_pin_bit_newf(h, HAL_IN, &ch->quick_stop, "cia402.%d.quick-stop", i);
    st = st ? st : hal_pin_s32_newf(h, HAL_OUT, &ch->state, "cia402.%d.state", i);
    st = st ? st : hal_pin_u32_newf(h, HAL_OUT, &ch->statusword, "cia402.%d.statusword", i);
    st = st ? st : hal_pin_u32_newf(h, HAL_OUT, &ch->emcy_code, "cia402.%d.emcy-code", i);
    return st;
}

/* The bus-wide pins. */
static int global_pins_new(struct hal *h, struct cia402_comp *c)
{
    int st = hal_pin_bit_newf(h, HAL_OUT, &c->fault_any, "cia402.fault-any");
    st = st ? st : hal_pin_bit_newf(h, HAL_OUT, &c->all_enabled, "cia402.all-enabled");
    st = st ? st : hal_pin_bit_newf(h, HAL_OUT, &c->bus_error, "cia402.bus-error");
    st = st ? st : hal_pin_bit_newf(h, HAL_OUT, &c->bus_off, "cia402.bus-off");
    st = st ? st : hal_pin_u32_newf(h, HAL_OUT, &c->tx_dropped, "cia402.tx-dropped");
    st = st ? st : hal_pin_u32_newf(h, HAL_OUT, &c->rx_errors, "cia402.rx-errors");
    st = st ? st : hal_pin_u32_newf(h, HAL_OUT, &c->err_frames, "cia402.error-frames");
    st = st ? st : hal_pin_u32_newf(h, HAL_OUT, &c->sync_count, "cia402.sync-count");
    return st;
}

/* `count=N`, else [KINS]JOINTS, else 6. */
static int parse_count(struct hal *h, int argc, char **argv, int *count)
{
    long n;
    if (ini_long(h, "KINS", "JOINTS", 6, false, &n))
        return HAL_ERR_SYNTAX;
    for (int i = 0; i < argc; i++) {
        char *end;
        if (strncmp(argv[i], "count=", 6) != 0)
            return hal_error(h, HAL_ERR_ARG, "cia402: unknown argument '%s' (expected "
                             "count=N)", argv[i]);
        n = strtol(argv[i] + 6, &end, 10);
        if (*end)
            n = 0;
    }
    if (n < 1 || n > CANOPEN_MASTER_MAX_NODES)
        return hal_error(h, HAL_ERR_ARG, "cia402: %ld drives: 1 to %d are supported", n,
                         CANOPEN_MASTER_MAX_NODES);
    *count = (int)n;
    return HAL_OK;
}

/* Closes the bus and frees the component at hal_destroy. */
static void cia402_free(void *arg)
{
    struct cia402_comp *c = arg;
    can_bus_close(&c->bus);
    free(c);
}

/* Opens [CAN]INTERFACE; the error names the INI file and the key. */
static int open_bus(struct hal *h, struct cia402_comp *c)
{
    const char *ifname = hal_ini_get(h, "CAN", "INTERFACE");
    char err[300];
    if (!ifname)
        return hal_error(h, HAL_ERR_COMPONENT, "cia402: %s: [CAN]INTERFACE is missing (a "
                         "SocketCAN interface such as can0, sim, or unix:PATH)",
                         hal_ini_path(h) ? hal_ini_path(h) : "(no INI file)");
    if (can_bus_open(&c->bus, ifname, err, sizeof err) != CAN_BUS_OK)
        return hal_error(h, HAL_ERR_COMPONENT, "cia402: %s: [CAN]INTERFACE = %s: %s",
                         hal_ini_path(h), ifname, err);
    if (c->bus.sim_peer_fd >= 0)
        return hal_set_object(h, CIA402_OBJ_SIM_PEER, &c->bus.sim_peer_fd);
    return HAL_OK;
}

/* `loadrt cia402 [count=N]`. */
static int cia402_load(struct hal *h, int argc, char **argv)
{
    int count = 0, st;
    long bitrate = 0, servo_ns = 0;
    struct canopen_master_cfg cfg;
    char err[CANOPEN_MSG_LEN];
    if ((st = parse_count(h, argc, argv, &count)) ||
        (st = read_cfg(h, count, &cfg, &bitrate, &servo_ns)) ||
        (st = check_bus_load(h, &cfg, bitrate)))
        return st;
    struct cia402_comp *c = calloc(1, sizeof *c);
    if (!c)
        return hal_error(h, HAL_ERR_NOMEM, "cia402: out of memory");
    c->h = h;
    c->bus.fd = c->bus.sim_peer_fd = -1;
    if ((st = hal_on_destroy(h, cia402_free, c))) {
        free(c);
        return st;
    }
    if (canopen_master_init(&c->m, &cfg, err, sizeof err) != CANOPEN_OK)
        return hal_error(h, HAL_ERR_COMPONENT, "cia402: %s: %s", hal_ini_path(h), err);
    if ((st = open_bus(h, c)) || (st = global_pins_new(h, c)))
        return st;
    for (int i = 0; i < count; i++)
        if ((st = chan_new(h, &c->chan[i], i)))
            return st;
    c->startup.budget_ns = canopen_master_startup_budget_ns(&c->m, servo_ns);
    c->startup.what = "CAN drives (cia402)";
    if ((st = hal_set_object(h, CIA402_OBJ_MASTER, &c->m)) ||
        (st = hal_set_object(h, DRIVE_STARTUP_OBJ_CIA402, &c->startup)))
        return st;
    return hal_export_functf(h, cia402_update, c, "cia402.update");
}

const struct hal_comp_type hal_comp_cia402 = { "cia402", cia402_load };
