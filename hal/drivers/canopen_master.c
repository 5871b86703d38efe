/* canopen_master.c: the master's per-cycle logic: NMT, SDO configuration, SYNC, PDOs, faults. */
#include "hal/drivers/canopen_master.h"

#include <inttypes.h>
#include <stdarg.h>
#include <stdio.h>

#include "hal/drivers/canopen_config.h"

#define MS_NS 1000000LL

/* Latches a fault on a node unless one is latched already (the first cause is the one the
 * machinist needs); the message starts with the node and the joint. */
static void node_fault(struct canopen_node *n, int status, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void node_fault(struct canopen_node *n, int status, const char *fmt, ...)
{
    if (n->fault)
        return;
    int k = snprintf(n->message, sizeof n->message, "CAN node %d (joint %d): ", n->cfg.node_id,
                     n->cfg.joint);
    va_list ap;
    va_start(ap, fmt);
    if (k > 0 && (size_t)k < sizeof n->message)
        vsnprintf(n->message + k, sizeof n->message - (size_t)k, fmt, ap);
    va_end(ap);
    n->fault = true;
    n->fault_status = status;
    n->message_new = true;
}

/* A communication fault: the node gets no PDOs until a fault reset restarts it. */
static void node_comm_fault(struct canopen_node *n, int status, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void node_comm_fault(struct canopen_node *n, int status, const char *fmt, ...)
{
    char text[CANOPEN_MSG_LEN];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    node_fault(n, status, "%s", text);
    n->phase = CANOPEN_PHASE_COMM_FAULT;
    n->state = CIA402_UNKNOWN;
    n->sdo_pending = false;
}

/* An SDO answer: the pending write is confirmed, or refused with an abort code. */
static void rx_sdo(struct canopen_master *m, struct canopen_node *n, const struct can_frame *f)
{
    struct canopen_sdo s;
    struct canopen_write w;
    if (n->phase != CANOPEN_PHASE_CONFIG || !n->sdo_pending || !canopen_sdo_decode(f, &s) ||
        !canopen_config_write(m, n, n->sdo_step, &w) || s.index != w.index || s.sub != w.sub)
        return;  /* not the answer we wait for */
    if (s.cmd == CANOPEN_SDO_ABORT) {
        node_comm_fault(n, CANOPEN_ERR_SDO_ABORT,
                        "the drive refused writing %" PRIu32 " to 0x%04X:%02X (%s): SDO abort "
                        "code 0x%08" PRIX32 " (%s)", w.value, w.index, w.sub, w.what, s.value,
                        canopen_abort_text(s.value));
        return;
    }
    if (s.cmd == CANOPEN_SDO_DOWNLOAD_RESP) {
        n->sdo_pending = false;
        n->sdo_step++;
    }
}

/* Heartbeat or boot-up (state 0). */
static void rx_heartbeat(struct canopen_node *n, const struct can_frame *f, int64_t now_ns)
{
    if (f->can_dlc < 1)
        return;
    uint8_t st = f->data[0] & 0x7Fu;  /* bit 7 is the (unused) toggle bit of node guarding */
    if (st == CANOPEN_STATE_BOOTUP) {
        /* A boot-up while the node is being configured starts its configuration over: it
         * may be the node's power-on message read after our NMT reset (the bus was joined
         * after the node booted, or the other process was slow), or the node rebooted. The
         * configuration is written again from the first entry; the SDO time-outs and the
         * runner's start-up wait still bound a node that keeps rebooting. */
        if (n->phase == CANOPEN_PHASE_WAIT_BOOT || n->phase == CANOPEN_PHASE_CONFIG) {
            n->phase = CANOPEN_PHASE_CONFIG;
            n->sdo_step = 0;
            n->sdo_pending = false;
            n->heartbeat_seen = false;
        } else if (n->phase == CANOPEN_PHASE_RUN) {
            node_comm_fault(n, CANOPEN_ERR_BOOT, "the drive restarted by itself (boot-up "
                            "message while running): check its supply and its fault log");
        }
        return;
    }
    n->heartbeat_seen = true;
    n->last_heartbeat_ns = now_ns;
    if (n->phase == CANOPEN_PHASE_RUN && st != CANOPEN_STATE_OPERATIONAL && n->actual_valid)
        node_comm_fault(n, CANOPEN_ERR_HEARTBEAT, "the drive left NMT Operational (heartbeat "
                        "reports state 0x%02X)", st);
}

/* TPDO1: statusword and position actual value. */
static void rx_tpdo(struct canopen_node *n, const struct can_frame *f, int64_t now_ns)
{
    uint16_t sw;
    int32_t pos;
    if (n->phase != CANOPEN_PHASE_RUN || !canopen_pdo_unpack(f, &sw, &pos))
        return;
    n->statusword = sw;
    n->state = cia402_decode(sw);
    n->actual_counts = pos;
    n->actual_valid = true;
    n->last_tpdo_ns = now_ns;
    n->position_fb_mm = canopen_counts_to_mm(&n->cfg, pos);
    n->fb_valid = true;
    if (cia402_is_fault(n->state)) {
        if (n->emcy_code)
            node_fault(n, CANOPEN_ERR_DRIVE_FAULT, "the drive reports %s (statusword 0x%04X), "
                       "last emergency code 0x%04X (%s)", cia402_state_name(n->state), sw,
                       n->emcy_code, canopen_emcy_text(n->emcy_code));
        else
            node_fault(n, CANOPEN_ERR_DRIVE_FAULT, "the drive reports %s (statusword 0x%04X)",
                       cia402_state_name(n->state), sw);
    } else if (n->reset_stage == 2) {
        n->reset_stage = 0;  /* the fault reset edge was taken */
        n->fault = false;
    }
}

/* EMCY: error code and register go to the pins; a non-zero code is a fault. */
static void rx_emcy(struct canopen_node *n, const struct can_frame *f)
{
    struct canopen_emcy_msg e;
    if (!canopen_emcy_decode(f, &e))
        return;
    n->emcy_code = e.code;
    n->emcy_reg = e.reg;
    if (e.code != 0)  /* 0x0000 announces that the drive's error was reset */
        node_fault(n, CANOPEN_ERR_EMCY, "emergency message: error code 0x%04X (%s), error "
                   "register 0x%02X", e.code, canopen_emcy_text(e.code), e.reg);
}

/* Consumes one received frame. */
void canopen_master_rx(struct canopen_master *m, const struct can_frame *f, int64_t now_ns)
{
    int id;
    enum canopen_kind k = canopen_classify(f, &id);
    m->rx_frames++;
    struct canopen_node *n = id ? canopen_master_node(m, id) : NULL;
    if (!n) {
        m->rx_ignored++;
        return;
    }
    switch (k) {
    case CANOPEN_KIND_SDO_TX: rx_sdo(m, n, f); break;
    case CANOPEN_KIND_HEARTBEAT: rx_heartbeat(n, f, now_ns); break;
    case CANOPEN_KIND_TPDO1: rx_tpdo(n, f, now_ns); break;
    case CANOPEN_KIND_EMCY: rx_emcy(n, f); break;
    default: m->rx_ignored++; break;
    }
}

/* Appends a frame to the output if there is room. */
static void emit(struct canopen_master *m, struct can_frame *out, int max, int *k,
                 const struct can_frame *f)
{
    if (*k < max)
        out[(*k)++] = *f;
    else
        m->tx_overflow++;
}

/* Timeouts that apply while a node is being configured or running. */
static void check_timeouts(struct canopen_master *m, struct canopen_node *n, int64_t now_ns)
{
    int64_t hb_ns = m->cfg.heartbeat_timeout_ms * MS_NS;
    if (n->heartbeat_seen && now_ns - n->last_heartbeat_ns > hb_ns) {
        node_comm_fault(n, CANOPEN_ERR_HEARTBEAT, "no heartbeat for more than %ld ms: the "
                        "drive is off the bus (check its power and the CAN cable)",
                        m->cfg.heartbeat_timeout_ms);
        return;
    }
    /* The TPDO comes once per SYNC: its absence is seen in SYNC periods, long before the
     * heartbeat, and before the stale feedback turns into a following error. */
    int64_t fb_ns = (int64_t)m->cfg.feedback_timeout_syncs * m->cfg.sync_period_ns;
    if (n->phase == CANOPEN_PHASE_RUN && now_ns - n->last_tpdo_ns > fb_ns)
        node_comm_fault(n, CANOPEN_ERR_PDO_TIMEOUT, "no position feedback (TPDO1) from node "
                        "%d for %.0f ms (more than %d SYNC periods of %g ms, [CAN]"
                        "FEEDBACK_TIMEOUT_SYNCS): the drive stopped sending its position",
                        n->cfg.node_id, (double)(now_ns - n->last_tpdo_ns) / 1e6,
                        m->cfg.feedback_timeout_syncs, (double)m->cfg.sync_period_ns / 1e6);
}

/* The non-cyclic part of one node: NMT, configuration writes, fault reset of a lost node. */
static void node_service(struct canopen_master *m, struct canopen_node *n, int64_t now_ns,
                         bool reset_edge, struct can_frame *out, int max, int *k)
{
    struct can_frame f;
    struct canopen_write w;
    switch (n->phase) {
    case CANOPEN_PHASE_RESET:
        canopen_nmt(&f, CANOPEN_NMT_RESET_COMM, n->cfg.node_id);
        emit(m, out, max, k, &f);
        n->phase = CANOPEN_PHASE_WAIT_BOOT;
        n->deadline_ns = now_ns + m->cfg.boot_timeout_ms * MS_NS;
        break;
    case CANOPEN_PHASE_WAIT_BOOT:
        if (now_ns > n->deadline_ns)
            node_comm_fault(n, CANOPEN_ERR_BOOT, "no boot-up message within %ld ms of NMT "
                            "reset communication: is NODE_ID right and the drive powered?",
                            m->cfg.boot_timeout_ms);
        break;
    case CANOPEN_PHASE_CONFIG:
        if (n->sdo_pending) {
            if (now_ns > n->deadline_ns && canopen_config_write(m, n, n->sdo_step, &w))
                node_comm_fault(n, CANOPEN_ERR_SDO_TIMEOUT, "no answer within %ld ms to "
                                "writing 0x%04X:%02X (%s) (SDO timeout)",
                                n->cfg.sdo_timeout_ms, w.index, w.sub, w.what);
        } else if (canopen_config_write(m, n, n->sdo_step, &w)) {
            canopen_sdo_write(&f, n->cfg.node_id, w.index, w.sub, w.value, w.size);
            emit(m, out, max, k, &f);
            n->sdo_pending = true;
            n->deadline_ns = now_ns + n->cfg.sdo_timeout_ms * MS_NS;
        } else {
            canopen_nmt(&f, CANOPEN_NMT_START, n->cfg.node_id);
            emit(m, out, max, k, &f);
            n->phase = CANOPEN_PHASE_RUN;
            n->actual_valid = false;
            n->last_tpdo_ns = now_ns;
            n->reset_stage = 0;
        }
        break;
    case CANOPEN_PHASE_COMM_FAULT:
        if (reset_edge) {
            n->fault = false;
            n->phase = CANOPEN_PHASE_RESET;
        }
        break;
    case CANOPEN_PHASE_RUN:
        if (reset_edge) {
            if (cia402_is_fault(n->state))
                n->reset_stage = 1;  /* bit 7 low for one SYNC, then the rising edge */
            else
                n->fault = false;    /* EMCY or range fault with the drive still healthy */
        }
        break;
    }
    if (n->phase == CANOPEN_PHASE_CONFIG || n->phase == CANOPEN_PHASE_RUN)
        check_timeouts(m, n, now_ns);
}

/* The RPDO of one running node: controlword and target position for the next SYNC. */
static void node_rpdo(struct canopen_master *m, struct canopen_node *n, struct can_frame *f)
{
    uint16_t cw;
    if (n->reset_stage == 1) {
        cw = CIA402_CW_DISABLE_VOLTAGE;
        n->reset_stage = 2;
    } else if (n->reset_stage == 2) {
        cw = CIA402_CW_FAULT_RESET;
    } else if (n->quick_stop &&
               (n->state == CIA402_OP_ENABLED || n->state == CIA402_QUICK_STOP)) {
        cw = CIA402_CW_QUICK_STOP;  /* transition 11, then held until released */
    } else {
        cw = cia402_next_controlword(n->state, n->enable);
    }
    /* Until the drive follows, it is told to stay where it is: enabling causes no jump. */
    int32_t target = n->actual_counts;
    if (n->state == CIA402_OP_ENABLED && cw == CIA402_CW_ENABLE_OP &&
        !canopen_mm_to_counts(&n->cfg, n->position_cmd_mm, &target)) {
        target = n->actual_counts;
        node_fault(n, CANOPEN_ERR_RANGE, "commanded leg length %.3f mm is beyond the drive's "
                   "32-bit position range (COUNTS_PER_MM %g)", n->position_cmd_mm,
                   n->cfg.counts_per_mm);
    }
    n->controlword = cw;
    canopen_pdo_pack(f, CANOPEN_COB_RPDO1 + (uint32_t)n->cfg.node_id, cw, target);
    (void)m;
}

/* Advances every node to now_ns and writes the frames to send. */
int canopen_master_step(struct canopen_master *m, int64_t now_ns, struct can_frame *out,
                        int max_out)
{
    int k = 0;
    for (int i = 0; i < m->cfg.n_nodes; i++) {
        struct canopen_node *n = &m->node[i];
        bool edge = n->fault_reset && !n->reset_prev;
        n->reset_prev = n->fault_reset;
        node_service(m, n, now_ns, edge, out, max_out, &k);
    }
    if (now_ns < m->next_sync_ns)
        return k;
    /* SYNC first: the nodes sample their TPDOs at it; the RPDOs that follow in the same
     * period are actuated at the next SYNC (CiA 301 synchronous PDO timing). */
    struct can_frame f;
    canopen_sync(&f);
    emit(m, out, max_out, &k, &f);
    m->sync_count++;
    m->next_sync_ns += m->cfg.sync_period_ns;
    if (m->next_sync_ns <= now_ns)  /* the caller fell behind: do not burst SYNCs */
        m->next_sync_ns = now_ns + m->cfg.sync_period_ns;
    for (int i = 0; i < m->cfg.n_nodes; i++) {
        struct canopen_node *n = &m->node[i];
        if (n->phase != CANOPEN_PHASE_RUN || !n->actual_valid)
            continue;  /* no target before the drive has told us where it is */
        node_rpdo(m, n, &f);
        emit(m, out, max_out, &k, &f);
    }
    return k;
}

/* True when every node runs in Operation enabled. */
bool canopen_master_all_enabled(const struct canopen_master *m)
{
    for (int i = 0; i < m->cfg.n_nodes; i++)
        if (m->node[i].phase != CANOPEN_PHASE_RUN || m->node[i].state != CIA402_OP_ENABLED)
            return false;
    return true;
}

/* Every node loses its bus at once; one message for all. */
void canopen_master_bus_lost(struct canopen_master *m, const char *why)
{
    for (int i = 0; i < m->cfg.n_nodes; i++) {
        struct canopen_node *n = &m->node[i];
        node_comm_fault(n, CANOPEN_ERR_BUS_LOST, "%s", why);
        n->message_new = false;
    }
}

/* Failed if any node has a fault latched, ready when all run with a statusword. */
enum canopen_startup canopen_master_startup(const struct canopen_master *m, int *failed_node)
{
    bool all_run = true;
    *failed_node = -1;
    for (int i = 0; i < m->cfg.n_nodes; i++) {
        const struct canopen_node *n = &m->node[i];
        if (n->fault) {
            *failed_node = i;
            return CANOPEN_FAILED;
        }
        all_run = all_run && n->phase == CANOPEN_PHASE_RUN && n->actual_valid;
    }
    return all_run ? CANOPEN_READY : CANOPEN_STARTING;
}

/* Nodes start in parallel; each waits for its boot-up, then writes one object per step_ns
 * (the servo period at least) and may wait SDO_TIMEOUT for each answer; then the NMT start
 * and the first TPDO (two SYNC periods) and the CiA 402 climb (three transitions, one per
 * SYNC). */
int64_t canopen_master_startup_budget_ns(const struct canopen_master *m, long step_ns)
{
    int64_t worst = 0;
    int64_t sync_ns = m->cfg.sync_period_ns;
    int writes = canopen_config_count();
    for (int i = 0; i < m->cfg.n_nodes; i++) {
        const struct canopen_node_cfg *c = &m->node[i].cfg;
        int64_t t = m->cfg.boot_timeout_ms * MS_NS +
                    (int64_t)writes * (c->sdo_timeout_ms * MS_NS + step_ns);
        if (t > worst)
            worst = t;
    }
    return worst + 6 * sync_ns + 2 * (int64_t)step_ns;
}

/* Looks a node up by its node-ID. */
struct canopen_node *canopen_master_node(struct canopen_master *m, int node_id)
{
    if (node_id < 1 || node_id > CANOPEN_NODE_MAX || !m->slot[node_id])
        return NULL;
    return &m->node[m->slot[node_id] - 1];
}
