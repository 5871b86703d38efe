/* cia402_sim.c: the simulated CiA 402 drive: NMT slave, PDOs, state machine, CSP position. */
#include "sim/cia402_sim.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "sim/cia402_sim_od.h"

/* The communication area after power-on or reset communication (CiA 301 defaults). */
static void reset_comm(struct cia402_sim *s)
{
    int n = s->cfg.node_id;
    s->heartbeat_ms = 0;
    s->rpdo_cob = CANOPEN_COB_RPDO1 + (uint32_t)n;
    s->rpdo_tt = 0xFF;
    s->tpdo_cob = CANOPEN_COB_TPDO1 + (uint32_t)n;
    s->tpdo_tt = 0xFF;
    s->rpdo_count = s->tpdo_count = 0;
    memset(s->rpdo_map, 0, sizeof s->rpdo_map);
    memset(s->tpdo_map, 0, sizeof s->tpdo_map);
    s->rpdo_fresh = false;
    s->nmt = CANOPEN_STATE_PREOP;
    s->boot_pending = true;
    s->boot_due_ns = INT64_MIN;  /* the caller's clock starts the start-up time */
}

/* Times a pending boot-up from now_ns if it is not timed yet. */
static void boot_schedule(struct cia402_sim *s, int64_t now_ns)
{
    if (s->boot_pending && s->boot_due_ns == INT64_MIN)
        s->boot_due_ns = now_ns + s->cfg.boot_delay_ns;
}

/* Power-on: dictionary defaults, drive Not ready to switch on. */
void cia402_sim_init(struct cia402_sim *s, const struct cia402_sim_cfg *cfg)
{
    memset(s, 0, sizeof *s);
    s->cfg = *cfg;
    s->actual_counts = s->target_counts = cfg->start_counts;
    s->state = CIA402_NOT_READY;
    s->quick_stop_option = 2;  /* the CiA 402 default: stop, then Switch on disabled */
    s->fault_code = 0x5000;  /* device hardware, unless the test says otherwise */
    s->fault_reg = 0x01;     /* generic error */
    reset_comm(s);
}

/* The statusword of a state (CiA 402 state coding) plus voltage, remote and CSP bits. */
static uint16_t statusword_of(enum cia402_state st)
{
    switch (st) {
    case CIA402_SWITCH_ON_DISABLED: return 0x0240;
    case CIA402_READY: return 0x0231;
    case CIA402_SWITCHED_ON: return 0x0233;
    case CIA402_OP_ENABLED: return 0x1237;  /* bit 12: the drive follows the target */
    case CIA402_QUICK_STOP: return 0x0217;
    case CIA402_FAULT_REACTION: return 0x021F;
    case CIA402_FAULT: return 0x0208;
    case CIA402_NOT_READY:
    default: return 0x0000;
    }
}

/* Transitions 2..12 and 16 of the device control state machine for one controlword. */
static enum cia402_state drive_transition(enum cia402_state st, uint16_t cw)
{
    enum cia402_command c = cia402_command_decode(cw);
    switch (st) {
    case CIA402_SWITCH_ON_DISABLED:
        return c == CIA402_CMD_SHUTDOWN ? CIA402_READY : st;
    case CIA402_READY:
        if (c == CIA402_CMD_SWITCH_ON || c == CIA402_CMD_ENABLE_OP)
            return CIA402_SWITCHED_ON;
        return c == CIA402_CMD_SHUTDOWN ? st : CIA402_SWITCH_ON_DISABLED;
    case CIA402_SWITCHED_ON:
        if (c == CIA402_CMD_ENABLE_OP)
            return CIA402_OP_ENABLED;
        if (c == CIA402_CMD_SHUTDOWN)
            return CIA402_READY;
        return c == CIA402_CMD_SWITCH_ON ? st : CIA402_SWITCH_ON_DISABLED;
    case CIA402_OP_ENABLED:
        switch (c) {
        case CIA402_CMD_SWITCH_ON: return CIA402_SWITCHED_ON;
        case CIA402_CMD_SHUTDOWN: return CIA402_READY;
        case CIA402_CMD_QUICK_STOP: return CIA402_QUICK_STOP;
        case CIA402_CMD_DISABLE_VOLTAGE: return CIA402_SWITCH_ON_DISABLED;
        default: return st;
        }
    case CIA402_QUICK_STOP:
        if (c == CIA402_CMD_DISABLE_VOLTAGE)
            return CIA402_SWITCH_ON_DISABLED;
        return c == CIA402_CMD_ENABLE_OP ? CIA402_OP_ENABLED : st;
    default:
        return st;
    }
}

/* The CSP position model: follow the target, at most max_velocity per interpolation period. */
static void follow_target(struct cia402_sim *s)
{
    double step = INFINITY;
    if (s->cfg.max_velocity_counts_s > 0.0 && s->interp_value)
        step = s->cfg.max_velocity_counts_s * s->interp_value * pow(10.0, s->interp_index);
    double d = (double)s->target_counts - (double)s->actual_counts;
    if (fabs(d) > step)
        d = d > 0 ? step : -step;
    s->actual_counts = (int32_t)((double)s->actual_counts + nearbyint(d));
}

/* Copies the stored RPDO into the objects its mapping names. */
static void apply_rpdo(struct cia402_sim *s)
{
    unsigned bytepos = 0;
    for (unsigned i = 0; i < s->rpdo_count && i < 4; i++) {
        uint32_t e = s->rpdo_map[i];
        const struct cia402_sim_obj *o = cia402_sim_od_find((uint16_t)(e >> 16), (uint8_t)(e >> 8));
        if (!o || bytepos + o->size > s->rpdo_len)
            return;  /* a short RPDO: CiA 301 would send EMCY 0x8210; the sim ignores it */
        uint32_t v = 0;
        for (unsigned b = 0; b < o->size; b++)
            v |= (uint32_t)s->rpdo_data[bytepos + b] << (8 * b);
        cia402_sim_od_set(s, o, v);
        bytepos += o->size;
    }
}

/* Builds the TPDO from the objects its mapping names. */
static void build_tpdo(const struct cia402_sim *s, struct can_frame *f)
{
    memset(f, 0, sizeof *f);
    f->can_id = s->tpdo_cob & CAN_SFF_MASK;
    unsigned bytepos = 0;
    for (unsigned i = 0; i < s->tpdo_count && i < 4; i++) {
        uint32_t e = s->tpdo_map[i];
        const struct cia402_sim_obj *o = cia402_sim_od_find((uint16_t)(e >> 16), (uint8_t)(e >> 8));
        if (!o || bytepos + o->size > 8)
            break;
        uint32_t v = cia402_sim_od_get(s, o);
        for (unsigned b = 0; b < o->size; b++)
            f->data[bytepos + b] = (uint8_t)(v >> (8 * b));
        bytepos += o->size;
    }
    f->can_dlc = (uint8_t)bytepos;
}

/* One SYNC in Operational: actuate the RPDO, run the drive, answer with the TPDO. */
static int on_sync(struct cia402_sim *s, struct can_frame *out, int max)
{
    int k = 0;
    s->syncs++;
    if (s->rpdo_fresh && !(s->rpdo_cob & CANOPEN_PDO_COBID_INVALID))
        apply_rpdo(s);
    s->rpdo_fresh = false;
    uint16_t cw = s->controlword;
    enum cia402_state before = s->state;
    if (s->state == CIA402_FAULT_REACTION) {
        s->state = CIA402_FAULT;  /* the fault reaction (a stop) takes one period here */
    } else if (s->state == CIA402_FAULT) {
        if ((cw & CIA402_CW_FAULT_RESET) && !(s->cw_applied & CIA402_CW_FAULT_RESET)) {
            s->state = CIA402_SWITCH_ON_DISABLED;  /* transition 15 on the rising edge */
            if (k < max)
                canopen_emcy(&out[k++], s->cfg.node_id, 0x0000, 0x00);  /* error reset */
        }
    } else if (s->inject & CIA402_SIM_DRIVE_FAULT) {
        s->inject &= ~(unsigned)CIA402_SIM_DRIVE_FAULT;  /* one fault per injection */
        s->state = CIA402_FAULT_REACTION;                 /* transition 13 */
        if (k < max)
            canopen_emcy(&out[k++], s->cfg.node_id, s->fault_code, s->fault_reg);
    } else if (s->state == CIA402_QUICK_STOP && before == CIA402_QUICK_STOP &&
               s->quick_stop_option >= 0 && s->quick_stop_option <= 4) {
        s->state = CIA402_SWITCH_ON_DISABLED;  /* stopped: the option drops the power stage */
    } else {
        s->state = drive_transition(s->state, cw);
    }
    s->cw_applied = cw;
    if (s->state == CIA402_OP_ENABLED && before != CIA402_OP_ENABLED)
        s->target_counts = s->actual_counts;  /* no jump at enable, whatever was stored */
    if (s->state == CIA402_OP_ENABLED)
        follow_target(s);
    s->statusword = statusword_of(s->state);
    s->mode_display = s->mode;
    if (!(s->tpdo_cob & CANOPEN_PDO_COBID_INVALID) && s->tpdo_tt >= 1 && s->tpdo_tt <= 240 &&
        !(s->inject & CIA402_SIM_TPDO_STOP) && k < max)
        build_tpdo(s, &out[k++]);
    return k;
}

/* NMT node control addressed to this node (or to all). */
static void on_nmt(struct cia402_sim *s, const struct can_frame *f)
{
    if (f->can_dlc < 2 || (f->data[1] != 0 && f->data[1] != s->cfg.node_id))
        return;
    switch (f->data[0]) {
    case CANOPEN_NMT_START: s->nmt = CANOPEN_STATE_OPERATIONAL; break;
    case CANOPEN_NMT_STOP: s->nmt = CANOPEN_STATE_STOPPED; break;
    case CANOPEN_NMT_PREOP: s->nmt = CANOPEN_STATE_PREOP; break;
    case CANOPEN_NMT_RESET_NODE:
        s->state = CIA402_NOT_READY;
        reset_comm(s);
        break;
    case CANOPEN_NMT_RESET_COMM: reset_comm(s); break;
    default: break;
    }
}

/* Handles one frame from the bus. */
int cia402_sim_rx(struct cia402_sim *s, const struct can_frame *in, int64_t now_ns,
                  struct can_frame *out, int max_out)
{
    int node;
    if (s->inject & CIA402_SIM_SILENT)
        return 0;
    switch (canopen_classify(in, &node)) {
    case CANOPEN_KIND_NMT:
        on_nmt(s, in);
        boot_schedule(s, now_ns);  /* a reset's start-up time runs from its NMT frame */
        return 0;
    case CANOPEN_KIND_SYNC:
        return s->nmt == CANOPEN_STATE_OPERATIONAL ? on_sync(s, out, max_out) : 0;
    case CANOPEN_KIND_RPDO1:
        if (node != s->cfg.node_id || s->nmt != CANOPEN_STATE_OPERATIONAL)
            return 0;
        s->rpdo_len = in->can_dlc > 8 ? 8 : in->can_dlc;
        memcpy(s->rpdo_data, in->data, s->rpdo_len);
        s->rpdo_fresh = true;
        s->rpdos++;
        return 0;
    case CANOPEN_KIND_SDO_RX:
        if (node != s->cfg.node_id || s->nmt == CANOPEN_STATE_STOPPED ||
            (s->inject & CIA402_SIM_SDO_MUTE) || max_out < 1)
            return 0;
        return cia402_sim_sdo(s, in, &out[0]) ? 1 : 0;
    default:
        return 0;
    }
}

/* Boot-up after (re)start, then the heartbeat every 0x1017 ms; the drive leaves Not ready
 * to switch on by itself once its self-test is done (transition 1). */
int cia402_sim_step(struct cia402_sim *s, int64_t now_ns, struct can_frame *out, int max_out)
{
    int k = 0;
    if (s->state == CIA402_NOT_READY)
        s->state = CIA402_SWITCH_ON_DISABLED;
    s->statusword = statusword_of(s->state);
    if (s->inject & CIA402_SIM_SILENT)
        return 0;
    boot_schedule(s, now_ns);
    if (s->boot_pending && now_ns >= s->boot_due_ns && k < max_out) {
        canopen_heartbeat(&out[k++], s->cfg.node_id, CANOPEN_STATE_BOOTUP);
        s->boot_pending = false;
        s->next_heartbeat_ns = now_ns;
    }
    if (s->heartbeat_ms == 0 || (s->inject & CIA402_SIM_HEARTBEAT_STOP))
        return k;
    if (now_ns >= s->next_heartbeat_ns && k < max_out) {
        canopen_heartbeat(&out[k++], s->cfg.node_id, s->nmt);
        s->next_heartbeat_ns = now_ns + (int64_t)s->heartbeat_ms * 1000000;
    }
    return k;
}

/* Sets fault injection bits. */
void cia402_sim_inject(struct cia402_sim *s, unsigned faults)
{
    s->inject |= faults;
}

/* Clears fault injection bits. */
void cia402_sim_clear(struct cia402_sim *s, unsigned faults)
{
    s->inject &= ~faults;
}

/* The EMCY an injected drive fault sends. */
void cia402_sim_set_drive_fault(struct cia402_sim *s, uint16_t emcy_code, uint8_t error_reg)
{
    s->fault_code = emcy_code;
    s->fault_reg = error_reg;
}

/* The object whose writes an injected SDO abort refuses, and the code. */
void cia402_sim_set_abort(struct cia402_sim *s, uint16_t index, uint8_t sub, uint32_t code)
{
    s->abort_index = index;
    s->abort_sub = sub;
    s->abort_code = code;
}
