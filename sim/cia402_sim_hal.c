/* cia402_sim_hal.c: HAL component `cia402-sim`: simulated CiA 402 drives on the master's pair. */
#include <stdlib.h>
#include <string.h>

#include "hal/drivers/can_bus.h"
#include "hal/drivers/canopen_master.h"
#include "hal/drivers/cia402_hal.h"
#include "hal/hal.h"
#include "sim/cia402_sim.h"
#include "sim/cia402_sim_hal.h"

/*
 * `loadrt cia402-sim [count=N]` after `loadrt cia402` with [CAN]INTERFACE = sim: one
 * simulated drive per [CAN_NODE_i] (NODE_ID, COUNTS_PER_MM, OFFSET as the master reads them;
 * SIM_START = leg length at power-on, mm, default OFFSET; SIM_MAX_VELOCITY = following
 * limit, mm/s, default none; SIM_BOOT_DELAY = start-up time until the boot-up message, ms,
 * default 0). Its funct cia402-sim.update answers on the other end of the
 * socketpair; add it after cia402.update. Pins per drive (fault injection for tests and
 * demonstrations, and what the drive itself knows):
 *   cia402-sim.N.inject-fault    bit in   rising edge: drive fault, EMCY with fault-code
 *   cia402-sim.N.heartbeat-stop  bit in   no heartbeats while true
 *   cia402-sim.N.silent          bit in   the drive sends nothing while true
 *   cia402-sim.N.sdo-mute        bit in   SDO requests go unanswered while true
 *   cia402-sim.N.tpdo-stop       bit in   no TPDO (position feedback) while true
 *   cia402-sim.N.position-counts s32 out  position actual value, counts
 *   cia402-sim.N.state           s32 out  the drive's CiA 402 state
 *   cia402-sim.N.fault-code      u32 param (rw) EMCY error code of an injected fault
 */

#define SIM_MAX_DRIVES 16

/* One simulated drive and its pins. */
struct sim_chan {
    struct cia402_sim sim;       /* the drive model */
    bool *inject_fault;          /* in: rising edge injects a drive fault */
    bool *heartbeat_stop;        /* in: heartbeats stop while true */
    bool *silent;                /* in: nothing is sent while true */
    bool *sdo_mute;              /* in: SDO requests unanswered while true */
    bool *tpdo_stop;             /* in: no TPDOs while true */
    int32_t *position_counts;    /* out: position actual value */
    int32_t *state;              /* out: enum cia402_state */
    uint32_t fault_code;         /* param: EMCY code of an injected fault */
    bool inject_prev;            /* inject_fault last period, for the edge */
};

/* The component: the pair's far end and the drives. */
struct sim_comp {
    int fd;                      /* the drives' end of the socketpair (owned by cia402) */
    int count;                   /* drives */
    int64_t now_ns;              /* sum of the periods run */
    struct sim_chan chan[SIM_MAX_DRIVES];
};

/* Writes answers to the pair; a full queue drops them like a congested bus would. */
static void send_all(struct sim_comp *c, const struct can_frame *f, int n)
{
    for (int i = 0; i < n; i++)
        (void)can_fd_write(c->fd, &f[i]);
}

/* Fault-injection pins into the model. */
static void apply_pins(struct sim_chan *ch)
{
    unsigned bits[] = { CIA402_SIM_HEARTBEAT_STOP, CIA402_SIM_SILENT, CIA402_SIM_SDO_MUTE,
                        CIA402_SIM_TPDO_STOP };
    bool on[] = { *ch->heartbeat_stop, *ch->silent, *ch->sdo_mute, *ch->tpdo_stop };
    for (int b = 0; b < 4; b++) {
        if (on[b])
            cia402_sim_inject(&ch->sim, bits[b]);
        else
            cia402_sim_clear(&ch->sim, bits[b]);
    }
    if (*ch->inject_fault && !ch->inject_prev) {
        cia402_sim_set_drive_fault(&ch->sim, (uint16_t)ch->fault_code, 0x01);
        cia402_sim_inject(&ch->sim, CIA402_SIM_DRIVE_FAULT);
    }
    ch->inject_prev = *ch->inject_fault;
}

/* One period: every frame the master sent goes to every drive; answers go back. */
static void sim_update(void *arg, long period_ns)
{
    struct sim_comp *c = arg;
    struct can_frame in, out[CIA402_SIM_MAX_OUT];
    for (int i = 0; i < c->count; i++)
        apply_pins(&c->chan[i]);
    while (can_fd_read(c->fd, &in) == 1)
        for (int i = 0; i < c->count; i++)
            send_all(c, out, cia402_sim_rx(&c->chan[i].sim, &in, c->now_ns, out,
                                           CIA402_SIM_MAX_OUT));
    for (int i = 0; i < c->count; i++) {
        struct sim_chan *ch = &c->chan[i];
        send_all(c, out, cia402_sim_step(&ch->sim, c->now_ns, out, CIA402_SIM_MAX_OUT));
        *ch->position_counts = ch->sim.actual_counts;
        *ch->state = (int32_t)ch->sim.state;
    }
    c->now_ns += period_ns;
}

/* Drive i from [CAN_NODE_i] (also used by `hexcnc can_sim`). */
int cia402_sim_cfg_read(struct hal *h, int i, struct cia402_sim_cfg *sc)
{
    char sec[32];
    long id;
    double cpm, off = 0, start, vmax = 0, boot_ms = 0;
    snprintf(sec, sizeof sec, "CAN_NODE_%d", i);
    int st = hal_ini_int(h, sec, "NODE_ID", 0, &id);
    st = st ? st : hal_ini_double(h, sec, "COUNTS_PER_MM", 0, &cpm);
    if (st)
        return st;
    if (hal_ini_double(h, sec, "OFFSET", 0, &off) == HAL_ERR_SYNTAX ||
        hal_ini_double(h, sec, "SIM_START", off, &start) == HAL_ERR_SYNTAX ||
        hal_ini_double(h, sec, "SIM_MAX_VELOCITY", 0, &vmax) == HAL_ERR_SYNTAX ||
        hal_ini_double(h, sec, "SIM_BOOT_DELAY", 0, &boot_ms) == HAL_ERR_SYNTAX)
        return HAL_ERR_SYNTAX;
    if (!(boot_ms >= 0 && boot_ms <= 60000))
        return hal_error(h, HAL_ERR_ARG, "cia402-sim: %s: [%s]SIM_BOOT_DELAY = %g ms: 0 to "
                         "60000 ms", hal_ini_path(h), sec, boot_ms);
    sc->boot_delay_ns = (int64_t)(boot_ms * 1e6);
    sc->node_id = (int)id;
    sc->start_counts = (int32_t)((start - off) * cpm);
    sc->max_velocity_counts_s = vmax * (cpm < 0 ? -cpm : cpm);
    return HAL_OK;
}

/* The pins and parameter of drive i. */
static int chan_pins(struct hal *h, struct sim_chan *ch, int i)
{
    int st = hal_pin_bit_newf(h, HAL_IN, &ch->inject_fault, "cia402-sim.%d.inject-fault", i);
    st = st ? st : hal_pin_bit_newf(h, HAL_IN, &ch->heartbeat_stop, "cia402-sim.%d.heartbeat-stop", i);
    st = st ? st : hal_pin_bit_newf(h, HAL_IN, &ch->silent, "cia402-sim.%d.silent", i);
    st = st ? st : hal_pin_bit_newf(h, HAL_IN, &ch->sdo_mute, "cia402-sim.%d.sdo-mute", i);
    st = st ? st : hal_pin_bit_newf(h, HAL_IN, &ch->tpdo_stop, "cia402-sim.%d.tpdo-stop", i);
    st = st ? st : hal_pin_s32_newf(h, HAL_OUT, &ch->position_counts, "cia402-sim.%d.position-counts", i);
    st = st ? st : hal_pin_s32_newf(h, HAL_OUT, &ch->state, "cia402-sim.%d.state", i);
    st = st ? st : hal_param_u32_newf(h, HAL_RW, &ch->fault_code, "cia402-sim.%d.fault-code", i);
    ch->fault_code = 0x2310;  /* continuous over-current: a typical servo trip */
    return st;
}

/* `loadrt cia402-sim [count=N]`: N defaults to the master's drive count. */
static int sim_load(struct hal *h, int argc, char **argv)
{
    int *peer = hal_get_object(h, CIA402_OBJ_SIM_PEER);
    const struct canopen_master *m = hal_get_object(h, CIA402_OBJ_MASTER);
    if (!peer || *peer < 0 || !m)
        return hal_error(h, HAL_ERR_COMPONENT, "cia402-sim: load cia402 first, with "
                         "[CAN]INTERFACE = sim, so that there is a simulated bus to answer on");
    int count = m->cfg.n_nodes;
    for (int i = 0; i < argc; i++)
        if (strncmp(argv[i], "count=", 6) == 0)
            count = atoi(argv[i] + 6);
        else
            return hal_error(h, HAL_ERR_ARG, "cia402-sim: unknown argument '%s'", argv[i]);
    if (count < 1 || count > SIM_MAX_DRIVES)
        return hal_error(h, HAL_ERR_ARG, "cia402-sim: count must be 1..%d", SIM_MAX_DRIVES);
    struct sim_comp *c = calloc(1, sizeof *c);
    if (!c)
        return hal_error(h, HAL_ERR_NOMEM, "cia402-sim: out of memory");
    int st = hal_on_destroy(h, free, c);
    if (st) {
        free(c);
        return st;
    }
    c->fd = *peer;
    c->count = count;
    for (int i = 0; i < count; i++) {
        struct cia402_sim_cfg sc = { 0 };
        if ((st = cia402_sim_cfg_read(h, i, &sc)) || (st = chan_pins(h, &c->chan[i], i)))
            return st;
        cia402_sim_init(&c->chan[i].sim, &sc);
    }
    return hal_export_functf(h, sim_update, c, "cia402-sim.update");
}

const struct hal_comp_type hal_comp_cia402_sim = { "cia402-sim", sim_load };
