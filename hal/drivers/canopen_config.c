/* canopen_config.c: the master's configuration: checks, SDO write list, units, PDO layout. */
#include "hal/drivers/canopen_config.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/*
 * The writes that put a node into CSP with the fixed PDO mapping, in order. CiA 301's PDO
 * mapping rules: a PDO is switched off through bit 31 of its COB-ID before its mapping
 * changes, the mapping count goes to 0 while entries are written, then the count and the
 * COB-ID are restored.
 */
enum { ADD_NODE = 1, INTERP_VALUE = 2, INTERP_INDEX = 3, HB_PERIOD = 4 };
static const struct {
    uint16_t index;
    uint8_t sub;
    uint8_t size;         /* bytes */
    uint8_t value_from;   /* 0: value as is; else one of the enum above */
    uint32_t value;
    const char *what;     /* for messages */
} config_writes[] = {
    { CANOPEN_OD_HEARTBEAT_PRODUCER, 0, 2, HB_PERIOD, 0, "heartbeat producer time" },
    { CIA402_OD_MODES_OF_OP, 0, 1, 0, CIA402_MODE_CSP, "modes of operation (8 = CSP)" },
    { CIA402_OD_QUICK_STOP_OPTION, 0, 2, 0, CIA402_QUICK_STOP_HOLD,
      "quick stop option code (6 = stop and hold in Quick stop active)" },
    { CIA402_OD_INTERP_PERIOD, 1, 1, INTERP_VALUE, 0, "interpolation time period value" },
    { CIA402_OD_INTERP_PERIOD, 2, 1, INTERP_INDEX, 0, "interpolation time index" },
    { CANOPEN_OD_RPDO1_COMM, 1, 4, ADD_NODE, CANOPEN_PDO_COBID_INVALID | CANOPEN_COB_RPDO1,
      "RPDO1 COB-ID (PDO off)" },
    { CANOPEN_OD_RPDO1_COMM, 2, 1, 0, CANOPEN_PDO_TT_SYNC1, "RPDO1 transmission type" },
    { CANOPEN_OD_RPDO1_MAP, 0, 1, 0, 0, "RPDO1 mapping count (clear)" },
    { CANOPEN_OD_RPDO1_MAP, 1, 4, 0, CANOPEN_PDO_MAP_ENTRY(CIA402_OD_CONTROLWORD, 0, 16),
      "RPDO1 mapping: controlword" },
    { CANOPEN_OD_RPDO1_MAP, 2, 4, 0, CANOPEN_PDO_MAP_ENTRY(CIA402_OD_TARGET_POSITION, 0, 32),
      "RPDO1 mapping: target position" },
    { CANOPEN_OD_RPDO1_MAP, 0, 1, 0, 2, "RPDO1 mapping count" },
    { CANOPEN_OD_RPDO1_COMM, 1, 4, ADD_NODE, CANOPEN_COB_RPDO1, "RPDO1 COB-ID (PDO on)" },
    { CANOPEN_OD_TPDO1_COMM, 1, 4, ADD_NODE, CANOPEN_PDO_COBID_INVALID | CANOPEN_COB_TPDO1,
      "TPDO1 COB-ID (PDO off)" },
    { CANOPEN_OD_TPDO1_COMM, 2, 1, 0, CANOPEN_PDO_TT_SYNC1, "TPDO1 transmission type" },
    { CANOPEN_OD_TPDO1_MAP, 0, 1, 0, 0, "TPDO1 mapping count (clear)" },
    { CANOPEN_OD_TPDO1_MAP, 1, 4, 0, CANOPEN_PDO_MAP_ENTRY(CIA402_OD_STATUSWORD, 0, 16),
      "TPDO1 mapping: statusword" },
    { CANOPEN_OD_TPDO1_MAP, 2, 4, 0, CANOPEN_PDO_MAP_ENTRY(CIA402_OD_POSITION_ACTUAL, 0, 32),
      "TPDO1 mapping: position actual value" },
    { CANOPEN_OD_TPDO1_MAP, 0, 1, 0, 2, "TPDO1 mapping count" },
    { CANOPEN_OD_TPDO1_COMM, 1, 4, ADD_NODE, CANOPEN_COB_TPDO1, "TPDO1 COB-ID (PDO on)" },
};

/* Number of configuration writes per node. */
int canopen_config_count(void)
{
    return (int)(sizeof config_writes / sizeof config_writes[0]);
}

/* The step-th configuration write for node n, with its value resolved. */
bool canopen_config_write(const struct canopen_master *m, const struct canopen_node *n, int step,
                          struct canopen_write *w)
{
    if (step < 0 || step >= canopen_config_count())
        return false;
    w->index = config_writes[step].index;
    w->sub = config_writes[step].sub;
    w->size = config_writes[step].size;
    w->what = config_writes[step].what;
    w->value = config_writes[step].value;
    switch (config_writes[step].value_from) {
    case ADD_NODE: w->value += (uint32_t)n->cfg.node_id; break;
    case INTERP_VALUE: w->value = m->interp_value; break;
    case INTERP_INDEX: w->value = (uint8_t)m->interp_index; break;
    case HB_PERIOD: w->value = (uint32_t)m->cfg.heartbeat_period_ms; break;
    default: break;
    }
    return true;
}

/*
 * 0x60C2 gives the interpolation period as value * 10^index seconds with an 8-bit value
 * (CiA 402, object 0x60C2). Picks the largest power of ten that divides the period exactly.
 */
static bool interp_period(long period_ns, uint8_t *value, int8_t *index)
{
    long unit_ns = 1000000000L;
    for (int e = 0; e >= -9; e--, unit_ns /= 10) {
        if (period_ns % unit_ns == 0 && period_ns / unit_ns <= 255) {
            *value = (uint8_t)(period_ns / unit_ns);
            *index = (int8_t)e;
            return true;
        }
    }
    return false;
}

/* Checks one node's configuration; writes a message on failure. */
static bool node_cfg_ok(const struct canopen_master_cfg *cfg, int i, char *err, size_t len)
{
    const struct canopen_node_cfg *c = &cfg->node[i];
    if (c->node_id < 1 || c->node_id > CANOPEN_NODE_MAX) {
        snprintf(err, len, "joint %d: NODE_ID %d is not a CANopen node-ID (1..127)", c->joint,
                 c->node_id);
        return false;
    }
    for (int j = 0; j < i; j++)
        if (cfg->node[j].node_id == c->node_id) {
            snprintf(err, len, "joints %d and %d both use NODE_ID %d", cfg->node[j].joint,
                     c->joint, c->node_id);
            return false;
        }
    if (!(fabs(c->counts_per_mm) > 0.0) || !isfinite(c->counts_per_mm)) {
        snprintf(err, len, "joint %d: COUNTS_PER_MM must be a non-zero number", c->joint);
        return false;
    }
    if (c->sdo_timeout_ms < 1) {
        snprintf(err, len, "joint %d: SDO_TIMEOUT must be at least 1 ms", c->joint);
        return false;
    }
    return true;
}

/* Checks the bus-wide values; writes a message on failure. */
static bool bus_cfg_ok(const struct canopen_master_cfg *cfg, char *err, size_t len)
{
    if (cfg->n_nodes < 1 || cfg->n_nodes > CANOPEN_MASTER_MAX_NODES) {
        snprintf(err, len, "%d drives: this master handles 1 to %d", cfg->n_nodes,
                 CANOPEN_MASTER_MAX_NODES);
        return false;
    }
    if (cfg->sync_period_ns < 100000) {
        snprintf(err, len, "SYNC_PERIOD %ld ns is below 100 us", cfg->sync_period_ns);
        return false;
    }
    if (cfg->heartbeat_period_ms < 1 || cfg->heartbeat_period_ms > 65535) {
        snprintf(err, len, "HEARTBEAT_PERIOD %ld ms is outside 1..65535 (object 0x1017)",
                 cfg->heartbeat_period_ms);
        return false;
    }
    if (cfg->heartbeat_timeout_ms <= cfg->heartbeat_period_ms) {
        snprintf(err, len, "HEARTBEAT_TIMEOUT %ld ms must exceed HEARTBEAT_PERIOD %ld ms",
                 cfg->heartbeat_timeout_ms, cfg->heartbeat_period_ms);
        return false;
    }
    if (cfg->boot_timeout_ms < 1) {
        snprintf(err, len, "BOOT_TIMEOUT must be at least 1 ms");
        return false;
    }
    if (cfg->feedback_timeout_syncs < 0 ||
        cfg->feedback_timeout_syncs > CANOPEN_FEEDBACK_SYNCS_MAX) {
        snprintf(err, len, "FEEDBACK_TIMEOUT_SYNCS %d is outside 1..%d SYNC periods",
                 cfg->feedback_timeout_syncs, CANOPEN_FEEDBACK_SYNCS_MAX);
        return false;
    }
    return true;
}

/* Checks the configuration and puts every node into RESET. */
int canopen_master_init(struct canopen_master *m, const struct canopen_master_cfg *cfg,
                        char *err, size_t errlen)
{
    memset(m, 0, sizeof *m);
    if (!bus_cfg_ok(cfg, err, errlen))
        return CANOPEN_ERR_ARG;
    for (int i = 0; i < cfg->n_nodes; i++)
        if (!node_cfg_ok(cfg, i, err, errlen))
            return CANOPEN_ERR_ARG;
    if (!interp_period(cfg->sync_period_ns, &m->interp_value, &m->interp_index)) {
        snprintf(err, errlen, "SYNC_PERIOD %ld ns cannot be written as value * 10^index s "
                 "with a value below 256 (object 0x60C2)", cfg->sync_period_ns);
        return CANOPEN_ERR_ARG;
    }
    m->cfg = *cfg;
    if (m->cfg.feedback_timeout_syncs == 0)
        m->cfg.feedback_timeout_syncs = CANOPEN_FEEDBACK_SYNCS_DEFAULT;
    for (int i = 0; i < cfg->n_nodes; i++) {
        m->node[i].cfg = cfg->node[i];
        m->node[i].phase = CANOPEN_PHASE_RESET;
        m->slot[cfg->node[i].node_id] = (uint8_t)(i + 1);
    }
    return CANOPEN_OK;
}

/* Leg length of a drive position. */
double canopen_counts_to_mm(const struct canopen_node_cfg *c, int32_t counts)
{
    return c->offset_mm + (double)counts / c->counts_per_mm;
}

/* Drive position of a leg length, rounded to the nearest count. */
bool canopen_mm_to_counts(const struct canopen_node_cfg *c, double mm, int32_t *counts)
{
    double x = nearbyint((mm - c->offset_mm) * c->counts_per_mm);
    if (!(x >= (double)INT32_MIN && x <= (double)INT32_MAX))
        return false;  /* also catches NaN */
    *counts = (int32_t)x;
    return true;
}

/* Six data bytes: the 16-bit word (controlword or statusword), then the 32-bit position. */
void canopen_pdo_pack(struct can_frame *f, uint32_t cob, uint16_t word, int32_t position)
{
    memset(f, 0, sizeof *f);
    f->can_id = cob;
    f->can_dlc = 6;
    canopen_put_u16(f->data, word);
    canopen_put_u32(f->data + 2, (uint32_t)position);
}

/* The reverse of canopen_pdo_pack; false for a frame shorter than six bytes. */
bool canopen_pdo_unpack(const struct can_frame *f, uint16_t *word, int32_t *position)
{
    if (f->can_dlc < 6)
        return false;
    *word = canopen_get_u16(f->data);
    *position = (int32_t)canopen_get_u32(f->data + 2);
    return true;
}
