/* test_cia402_master.c: the CANopen master against simulated CiA 402 drives, in process. */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hal/drivers/canopen_config.h"
#include "hal/drivers/canopen_master.h"
#include "sim/cia402_sim.h"

#define MAX_NODES 6
#define CYCLE_NS 1000000LL   /* 1 ms: the HAL servo period of the tests */
#define QUEUE 256

/* A master and its drives on an ideal bus, advanced one servo period at a time. */
struct rig {
    struct canopen_master m;
    struct cia402_sim sim[MAX_NODES];
    int n;
    int64_t now_ns;                      /* simulated time */
    struct can_frame q[QUEUE];           /* frames from the drives, read next cycle */
    int nq;
    uint16_t cw_seen[64];                /* distinct controlwords node 1 received, in order */
    int ncw;
};

/* Six (or n) drives, node-IDs 1..n, 1000 counts/mm, leg 600 mm at count 0. */
static void rig_init(struct rig *r, int n, long sync_ns)
{
    memset(r, 0, sizeof *r);
    r->n = n;
    struct canopen_master_cfg cfg = { .n_nodes = n, .sync_period_ns = sync_ns,
                                      .heartbeat_period_ms = 20, .heartbeat_timeout_ms = 100,
                                      .boot_timeout_ms = 500 };
    for (int i = 0; i < n; i++) {
        cfg.node[i] = (struct canopen_node_cfg){ .node_id = i + 1, .joint = i,
                                                 .counts_per_mm = 1000.0, .offset_mm = 600.0,
                                                 .sdo_timeout_ms = 50 };
        struct cia402_sim_cfg sc = { .node_id = i + 1, .start_counts = 1000 * i };
        cia402_sim_init(&r->sim[i], &sc);
    }
    char err[200];
    ck_assert_int_eq(canopen_master_init(&r->m, &cfg, err, sizeof err), CANOPEN_OK);
}

/* Appends frames from the drives to the master's queue. */
static void enqueue(struct rig *r, const struct can_frame *f, int k)
{
    for (int i = 0; i < k; i++) {
        ck_assert_int_lt(r->nq, QUEUE);
        r->q[r->nq++] = f[i];
    }
}

/* One servo period: master reads, master sends, drives answer, drives' timers. */
static void rig_cycle(struct rig *r)
{
    for (int i = 0; i < r->nq; i++)
        canopen_master_rx(&r->m, &r->q[i], r->now_ns);
    r->nq = 0;
    struct can_frame out[CANOPEN_MASTER_MAX_TX(MAX_NODES)], ans[CIA402_SIM_MAX_OUT];
    int k = canopen_master_step(&r->m, r->now_ns, out, CANOPEN_MASTER_MAX_TX(MAX_NODES));
    for (int i = 0; i < k; i++) {
        if (out[i].can_id == 0x201) {
            uint16_t cw = (uint16_t)(out[i].data[0] | out[i].data[1] << 8);
            if (r->ncw == 0 || (r->cw_seen[r->ncw - 1] != cw && r->ncw < 64))
                r->cw_seen[r->ncw++] = cw;
        }
        for (int s = 0; s < r->n; s++)
            enqueue(r, ans, cia402_sim_rx(&r->sim[s], &out[i], r->now_ns, ans, CIA402_SIM_MAX_OUT));
    }
    for (int s = 0; s < r->n; s++)
        enqueue(r, ans, cia402_sim_step(&r->sim[s], r->now_ns, ans, CIA402_SIM_MAX_OUT));
    r->now_ns += CYCLE_NS;
}

/* Runs ms servo periods. */
static void rig_run_ms(struct rig *r, int ms)
{
    for (int i = 0; i < ms; i++)
        rig_cycle(r);
}

/* Sets every node's enable input. */
static void rig_enable(struct rig *r, bool on)
{
    for (int i = 0; i < r->n; i++)
        r->m.node[i].enable = on;
}

/* Startup: NMT reset, boot-up, 18 SDO writes, NMT start; the drives hold the configuration. */
START_TEST(test_startup_configures_nodes)
{
    struct rig r;
    rig_init(&r, MAX_NODES, 2000000);
    rig_run_ms(&r, 100);
    for (int i = 0; i < r.n; i++) {
        const struct cia402_sim *s = &r.sim[i];
        ck_assert_int_eq(r.m.node[i].phase, CANOPEN_PHASE_RUN);
        ck_assert_int_eq(r.m.node[i].fault, false);
        ck_assert_int_eq(s->nmt, CANOPEN_STATE_OPERATIONAL);
        ck_assert_uint_eq(s->sdo_writes, (unsigned)canopen_config_count());
        ck_assert_int_eq(s->mode, 8);
        ck_assert_uint_eq(s->heartbeat_ms, 20);
        ck_assert_uint_eq(s->interp_value, 2);   /* 2 ms = 2 * 10^-3 s */
        ck_assert_int_eq(s->interp_index, -3);
        ck_assert_uint_eq(s->rpdo_cob, 0x200u + (unsigned)(i + 1));
        ck_assert_uint_eq(s->tpdo_cob, 0x180u + (unsigned)(i + 1));
        ck_assert_uint_eq(s->rpdo_tt, 1);
        ck_assert_uint_eq(s->tpdo_tt, 1);
        ck_assert_uint_eq(s->rpdo_count, 2);
        ck_assert_uint_eq(s->rpdo_map[0], 0x60400010u);
        ck_assert_uint_eq(s->rpdo_map[1], 0x607A0020u);
        ck_assert_uint_eq(s->tpdo_count, 2);
        ck_assert_uint_eq(s->tpdo_map[0], 0x60410010u);
        ck_assert_uint_eq(s->tpdo_map[1], 0x60640020u);
        /* TPDOs flow: the master knows the drive's position and state */
        ck_assert_int_eq(r.m.node[i].state, CIA402_SWITCH_ON_DISABLED);
        ck_assert_double_eq_tol(r.m.node[i].position_fb_mm, 600.0 + i, 1e-9);
    }
    /* one SYNC every 2 ms */
    ck_assert_uint_ge(r.m.sync_count, 45);
    ck_assert_uint_le(r.m.sync_count, 50);
}
END_TEST

/* Switch on disabled -> Ready -> Switched on -> Operation enabled with 0x06, 0x07, 0x0F. */
START_TEST(test_state_machine_to_enabled)
{
    struct rig r;
    rig_init(&r, 2, 1000000);
    rig_run_ms(&r, 80);
    ck_assert_int_eq(r.m.node[0].state, CIA402_SWITCH_ON_DISABLED);
    r.ncw = 0;
    rig_enable(&r, true);
    enum cia402_state seen[8];
    int nseen = 0;
    for (int i = 0; i < 20; i++) {
        rig_cycle(&r);
        enum cia402_state st = r.m.node[0].state;
        if (nseen == 0 || seen[nseen - 1] != st)
            seen[nseen++] = st;
    }
    ck_assert_int_eq(nseen, 4);
    ck_assert_int_eq(seen[0], CIA402_SWITCH_ON_DISABLED);
    ck_assert_int_eq(seen[1], CIA402_READY);
    ck_assert_int_eq(seen[2], CIA402_SWITCHED_ON);
    ck_assert_int_eq(seen[3], CIA402_OP_ENABLED);
    ck_assert_int_ge(r.ncw, 3);
    ck_assert_uint_eq(r.cw_seen[r.ncw - 3], 0x06);
    ck_assert_uint_eq(r.cw_seen[r.ncw - 2], 0x07);
    ck_assert_uint_eq(r.cw_seen[r.ncw - 1], 0x0F);
    ck_assert(canopen_master_all_enabled(&r.m));
    /* disabling goes back down: shutdown (0x06) to Ready, disable voltage (0x00) on down */
    rig_enable(&r, false);
    rig_run_ms(&r, 3);
    ck_assert_int_eq(r.m.node[0].state, CIA402_READY);
    rig_run_ms(&r, 3);
    ck_assert_int_eq(r.m.node[0].state, CIA402_SWITCH_ON_DISABLED);
    ck_assert_int_eq(r.sim[0].state, CIA402_SWITCH_ON_DISABLED);
}
END_TEST

/* In Operation enabled the drives follow a ramp; the feedback lags by one or two SYNCs. */
START_TEST(test_follows_commands)
{
    struct rig r;
    rig_init(&r, MAX_NODES, 1000000);
    rig_run_ms(&r, 80);
    for (int i = 0; i < r.n; i++)
        r.m.node[i].position_cmd_mm = r.m.node[i].position_fb_mm;
    rig_enable(&r, true);
    rig_run_ms(&r, 10);
    ck_assert(canopen_master_all_enabled(&r.m));
    const double v_mm_ms = 0.05;  /* 50 mm/s */
    for (int t = 0; t < 200; t++) {
        for (int i = 0; i < r.n; i++)
            r.m.node[i].position_cmd_mm += v_mm_ms * (i % 2 ? -1 : 1);
        rig_cycle(&r);
    }
    for (int i = 0; i < r.n; i++) {
        double lag_mm = (r.m.node[i].position_cmd_mm - r.m.node[i].position_fb_mm) *
                        (i % 2 ? -1 : 1);
        ck_assert_msg(lag_mm >= v_mm_ms - 1e-6 && lag_mm <= 3 * v_mm_ms + 1e-6,
                      "node %d lags %g mm", i + 1, lag_mm);
        /* the master's feedback is the drive's position one TPDO ago */
        double drive_mm = 600.0 + r.sim[i].actual_counts / 1000.0;
        ck_assert_double_eq_tol(r.m.node[i].position_fb_mm, drive_mm, v_mm_ms + 1e-9);
    }
}
END_TEST

/* An SDO abort at startup: fault with node, object, abort code and its meaning. */
START_TEST(test_sdo_abort)
{
    struct rig r;
    rig_init(&r, 3, 1000000);
    cia402_sim_set_abort(&r.sim[1], 0x6060, 0, 0x06090030u);
    cia402_sim_inject(&r.sim[1], CIA402_SIM_SDO_ABORT);
    rig_run_ms(&r, 60);
    const struct canopen_node *n = &r.m.node[1];
    ck_assert(n->fault);
    ck_assert_int_eq(n->fault_status, CANOPEN_ERR_SDO_ABORT);
    ck_assert_int_eq(n->phase, CANOPEN_PHASE_COMM_FAULT);
    ck_assert_ptr_nonnull(strstr(n->message, "CAN node 2 (joint 1)"));
    ck_assert_ptr_nonnull(strstr(n->message, "0x6060:00"));
    ck_assert_ptr_nonnull(strstr(n->message, "0x06090030"));
    ck_assert_ptr_nonnull(strstr(n->message, "value range of parameter exceeded"));
    ck_assert(!r.m.node[0].fault && r.m.node[0].phase == CANOPEN_PHASE_RUN);
    /* the cause removed, a fault reset configures the node again */
    cia402_sim_clear(&r.sim[1], CIA402_SIM_SDO_ABORT);
    r.m.node[1].fault_reset = true;
    rig_run_ms(&r, 60);
    ck_assert(!n->fault);
    ck_assert_int_eq(n->phase, CANOPEN_PHASE_RUN);
}
END_TEST

/* A drive that accepts nothing it cannot do: a wrong mapping is refused by the sim's own
 * dictionary checks (not an injection), and the message carries the code's meaning. */
START_TEST(test_sdo_abort_from_dictionary)
{
    struct cia402_sim s;
    struct cia402_sim_cfg sc = { .node_id = 4 };
    cia402_sim_init(&s, &sc);
    struct can_frame req, ans;
    struct canopen_sdo a;
    canopen_sdo_write(&req, 4, 0x1600, 1, 0x60410010, 4);  /* statusword into an RPDO */
    ck_assert_int_eq(cia402_sim_rx(&s, &req, 0, &ans, 1), 1);
    ck_assert(canopen_sdo_decode(&ans, &a));
    ck_assert_uint_eq(ans.can_id, 0x584);
    ck_assert_uint_eq(a.cmd, 0x80);
    ck_assert_uint_eq(a.value, 0x06040041u);
    canopen_sdo_write(&req, 4, 0x6041, 0, 0, 2);
    cia402_sim_rx(&s, &req, 0, &ans, 1);
    ck_assert(canopen_sdo_decode(&ans, &a));
    ck_assert_uint_eq(a.value, 0x06010002u);  /* read-only */
    canopen_sdo_write(&req, 4, 0x2000, 0, 0, 2);
    cia402_sim_rx(&s, &req, 0, &ans, 1);
    ck_assert(canopen_sdo_decode(&ans, &a));
    ck_assert_uint_eq(a.value, 0x06020000u);  /* no such object */
    canopen_sdo_write(&req, 4, 0x6060, 0, 8, 1);
    cia402_sim_rx(&s, &req, 0, &ans, 1);
    ck_assert(canopen_sdo_decode(&ans, &a));
    ck_assert_uint_eq(a.cmd, 0x60);
    ck_assert_int_eq(s.mode, 8);
}
END_TEST

/* No SDO answer: the fault comes after SDO_TIMEOUT (50 ms), not before, and names the object. */
START_TEST(test_sdo_timeout)
{
    struct rig r;
    rig_init(&r, 1, 1000000);
    cia402_sim_inject(&r.sim[0], CIA402_SIM_SDO_MUTE);
    rig_run_ms(&r, 50);  /* request at ~2 ms: not yet 50 ms without an answer */
    ck_assert(!r.m.node[0].fault);
    rig_run_ms(&r, 5);
    ck_assert(r.m.node[0].fault);
    ck_assert_int_eq(r.m.node[0].fault_status, CANOPEN_ERR_SDO_TIMEOUT);
    ck_assert_ptr_nonnull(strstr(r.m.node[0].message, "no answer within 50 ms"));
    ck_assert_ptr_nonnull(strstr(r.m.node[0].message, "0x1017:00"));
}
END_TEST

/* NMT: a node that never boots is reported; a node that reboots while running too. */
START_TEST(test_nmt_boot)
{
    struct rig r;
    rig_init(&r, 2, 1000000);
    cia402_sim_inject(&r.sim[1], CIA402_SIM_SILENT);
    rig_run_ms(&r, 520);
    ck_assert(r.m.node[1].fault);
    ck_assert_int_eq(r.m.node[1].fault_status, CANOPEN_ERR_BOOT);
    ck_assert_ptr_nonnull(strstr(r.m.node[1].message, "no boot-up message within 500 ms"));
    ck_assert_int_eq(r.m.node[0].phase, CANOPEN_PHASE_RUN);
    /* node 1 loses power and comes back: its boot-up while running is a fault */
    struct cia402_sim_cfg sc = r.sim[0].cfg;
    cia402_sim_init(&r.sim[0], &sc);
    rig_run_ms(&r, 3);
    ck_assert(r.m.node[0].fault);
    ck_assert_ptr_nonnull(strstr(r.m.node[0].message, "restarted"));
    /* fault reset: NMT reset communication, configuration, start again */
    r.m.node[0].fault_reset = true;
    rig_run_ms(&r, 60);
    ck_assert(!r.m.node[0].fault);
    ck_assert_int_eq(r.sim[0].nmt, CANOPEN_STATE_OPERATIONAL);
}
END_TEST

/* A boot-up read while a node is being configured (its power-on message arriving after the
 * master's NMT reset, or a reboot) starts the configuration over instead of faulting. */
START_TEST(test_bootup_during_config)
{
    struct rig r;
    rig_init(&r, 2, 1000000);
    rig_run_ms(&r, 3);
    ck_assert_int_eq(r.m.node[0].phase, CANOPEN_PHASE_CONFIG);
    ck_assert_uint_gt(r.sim[0].sdo_writes, 0);
    struct cia402_sim_cfg sc = r.sim[0].cfg;
    cia402_sim_init(&r.sim[0], &sc);  /* power cycle: its counters restart, a boot-up follows */
    rig_run_ms(&r, 100);
    ck_assert_msg(!r.m.node[0].fault, "%s", r.m.node[0].message);
    ck_assert_int_eq(r.m.node[0].phase, CANOPEN_PHASE_RUN);
    ck_assert_int_eq(r.sim[0].nmt, CANOPEN_STATE_OPERATIONAL);
    /* written again from the first entry (one request may have reached the restarted drive
     * before its boot-up was read): the drive holds the whole configuration */
    ck_assert_uint_ge(r.sim[0].sdo_writes, (unsigned)canopen_config_count());
    ck_assert_uint_le(r.sim[0].sdo_writes, (unsigned)canopen_config_count() + 1);
    ck_assert_int_eq(r.sim[0].mode, 8);
    ck_assert_uint_eq(r.sim[0].heartbeat_ms, 20);
    ck_assert_uint_eq(r.sim[0].tpdo_cob, 0x181u);
    ck_assert_int_eq(r.m.node[1].phase, CANOPEN_PHASE_RUN);
}
END_TEST

/* Drive fault with EMCY: fault pin, code and register in the message; fault reset brings
 * the drive back to Operation enabled through the state machine. */
START_TEST(test_fault_and_reset)
{
    struct rig r;
    rig_init(&r, 3, 1000000);
    rig_run_ms(&r, 80);
    rig_enable(&r, true);
    rig_run_ms(&r, 10);
    ck_assert(canopen_master_all_enabled(&r.m));
    cia402_sim_set_drive_fault(&r.sim[2], 0x2310, 0x03);
    cia402_sim_inject(&r.sim[2], CIA402_SIM_DRIVE_FAULT);
    rig_run_ms(&r, 5);
    struct canopen_node *n = &r.m.node[2];
    ck_assert(n->fault);
    ck_assert(n->message_new);
    ck_assert_uint_eq(n->emcy_code, 0x2310);
    ck_assert_uint_eq(n->emcy_reg, 0x03);
    ck_assert_int_eq(n->state, CIA402_FAULT);
    ck_assert_ptr_nonnull(strstr(n->message, "CAN node 3 (joint 2)"));
    ck_assert_ptr_nonnull(strstr(n->message, "error code 0x2310"));
    ck_assert_ptr_nonnull(strstr(n->message, "over-current"));
    ck_assert_ptr_nonnull(strstr(n->message, "error register 0x03"));
    ck_assert(!r.m.node[0].fault && r.m.node[0].state == CIA402_OP_ENABLED);
    /* still faulted without a reset */
    rig_run_ms(&r, 20);
    ck_assert(n->fault && n->state == CIA402_FAULT);
    n->fault_reset = true;
    enum cia402_state seen[10];
    int nseen = 0;
    for (int i = 0; i < 20; i++) {
        rig_cycle(&r);
        if (nseen == 0 || seen[nseen - 1] != n->state)
            seen[nseen++] = n->state;
    }
    ck_assert(!n->fault);
    ck_assert_uint_eq(n->emcy_code, 0);  /* the drive's EMCY 0x0000: error reset */
    ck_assert_int_eq(nseen, 5);
    ck_assert_int_eq(seen[0], CIA402_FAULT);
    ck_assert_int_eq(seen[1], CIA402_SWITCH_ON_DISABLED);
    ck_assert_int_eq(seen[4], CIA402_OP_ENABLED);
}
END_TEST

/* Heartbeat consumer: the loss is reported after HEARTBEAT_TIMEOUT (100 ms) of silence, not
 * earlier and no more than a period later. */
START_TEST(test_heartbeat_loss)
{
    struct rig r;
    rig_init(&r, 2, 1000000);
    rig_run_ms(&r, 80);
    rig_enable(&r, true);
    rig_run_ms(&r, 10);
    cia402_sim_inject(&r.sim[1], CIA402_SIM_HEARTBEAT_STOP);
    int64_t last_hb = r.m.node[1].last_heartbeat_ns;
    int64_t detected = -1;
    for (int i = 0; i < 200 && detected < 0; i++) {
        rig_cycle(&r);
        if (r.m.node[1].fault)
            detected = r.now_ns - CYCLE_NS;  /* the step of that cycle ran at now - 1 ms */
    }
    ck_assert_int_ge(detected, 0);
    /* at most a heartbeat already on the wire arrived after the stop */
    ck_assert_int_le(r.m.node[1].last_heartbeat_ns - last_hb, CYCLE_NS);
    int64_t silence_ns = detected - r.m.node[1].last_heartbeat_ns;
    ck_assert_int_gt(silence_ns, 100 * 1000000LL);
    ck_assert_int_le(silence_ns, 101 * 1000000LL);
    ck_assert_int_eq(r.m.node[1].fault_status, CANOPEN_ERR_HEARTBEAT);
    ck_assert_ptr_nonnull(strstr(r.m.node[1].message, "CAN node 2"));
    ck_assert_ptr_nonnull(strstr(r.m.node[1].message, "no heartbeat for more than 100 ms"));
    ck_assert(!r.m.node[0].fault);
    /* heartbeat back, fault reset: reconfigured and enabled again */
    cia402_sim_clear(&r.sim[1], CIA402_SIM_HEARTBEAT_STOP);
    r.m.node[1].fault_reset = true;
    rig_run_ms(&r, 80);
    ck_assert(!r.m.node[1].fault);
    ck_assert_int_eq(r.m.node[1].state, CIA402_OP_ENABLED);
}
END_TEST

/* Lost position feedback: a running drive whose TPDO1 stops (heartbeats going on) is
 * reported once more than FEEDBACK_TIMEOUT_SYNCS SYNC periods (default 3, at 2 ms: 6 ms)
 * passed without it, not before and within one servo period after; with the bound set
 * to 6 the same takes 12 ms. */
START_TEST(test_feedback_loss)
{
    for (int syncs = 0; syncs <= 6; syncs += 6) {
        struct rig r;
        rig_init(&r, 3, 2000000);
        if (syncs) {  /* a different bound through the configuration */
            struct canopen_master_cfg cfg = r.m.cfg;
            cfg.feedback_timeout_syncs = syncs;
            char err[200];
            ck_assert_int_eq(canopen_master_init(&r.m, &cfg, err, sizeof err), CANOPEN_OK);
        }
        int64_t bound_ns = (syncs ? syncs : 3) * 2000000LL;
        rig_run_ms(&r, 80);
        rig_enable(&r, true);
        rig_run_ms(&r, 20);
        ck_assert(canopen_master_all_enabled(&r.m));
        cia402_sim_inject(&r.sim[2], CIA402_SIM_TPDO_STOP);
        int64_t detected = -1;
        for (int i = 0; i < 200 && detected < 0; i++) {
            rig_cycle(&r);
            if (r.m.node[2].fault)
                detected = r.now_ns - CYCLE_NS;
        }
        struct canopen_node *n = &r.m.node[2];
        ck_assert_int_ge(detected, 0);
        int64_t silence_ns = detected - n->last_tpdo_ns;
        ck_assert_int_gt(silence_ns, bound_ns);
        ck_assert_int_le(silence_ns, bound_ns + CYCLE_NS);
        ck_assert_int_eq(n->fault_status, CANOPEN_ERR_PDO_TIMEOUT);
        char want[96];
        snprintf(want, sizeof want, "no position feedback (TPDO1) from node 3 for %lld ms",
                 (long long)(silence_ns / 1000000));
        ck_assert_msg(strstr(n->message, want) != NULL, "%s", n->message);
        ck_assert_ptr_nonnull(strstr(n->message, "CAN node 3 (joint 2)"));
        ck_assert(!r.m.node[0].fault && !r.m.node[1].fault);  /* the others go on */
        ck_assert(r.sim[2].heartbeat_ms > 0);  /* its heartbeat was on: not a lost node */
    }
    /* out of range */
    struct rig r;
    rig_init(&r, 1, 2000000);
    struct canopen_master_cfg cfg = r.m.cfg;
    cfg.feedback_timeout_syncs = -1;
    char err[200];
    ck_assert_int_eq(canopen_master_init(&r.m, &cfg, err, sizeof err), CANOPEN_ERR_ARG);
    ck_assert_ptr_nonnull(strstr(err, "FEEDBACK_TIMEOUT_SYNCS"));
}
END_TEST

/* Quick stop: an enabled drive goes to Quick stop active and holds its position whatever
 * the command does; released, it passes Switch on disabled and climbs back to enabled. */
START_TEST(test_quick_stop)
{
    struct rig r;
    rig_init(&r, 2, 1000000);
    rig_run_ms(&r, 80);
    for (int i = 0; i < r.n; i++)
        r.m.node[i].position_cmd_mm = r.m.node[i].position_fb_mm;
    rig_enable(&r, true);
    rig_run_ms(&r, 10);
    ck_assert(canopen_master_all_enabled(&r.m));
    r.m.node[0].quick_stop = true;
    rig_run_ms(&r, 4);
    ck_assert_int_eq(r.m.node[0].state, CIA402_QUICK_STOP);
    ck_assert_uint_eq(r.m.node[0].controlword, 0x02);
    int32_t held = r.sim[0].actual_counts;
    for (int t = 0; t < 50; t++) {
        r.m.node[0].position_cmd_mm += 0.01;
        r.m.node[1].position_cmd_mm += 0.01;
        rig_cycle(&r);
    }
    ck_assert_int_eq(r.sim[0].actual_counts, held);       /* held */
    ck_assert_int_eq(r.sim[1].actual_counts, 1000 + 490); /* the other one followed */
    ck_assert_int_eq(r.m.node[0].state, CIA402_QUICK_STOP);
    ck_assert(!r.m.node[0].fault);
    r.m.node[0].quick_stop = false;
    r.m.node[0].position_cmd_mm = r.m.node[0].position_fb_mm;
    enum cia402_state seen[8];
    int nseen = 0;
    for (int i = 0; i < 20; i++) {
        rig_cycle(&r);
        if (nseen == 0 || (seen[nseen - 1] != r.m.node[0].state && nseen < 8))
            seen[nseen++] = r.m.node[0].state;
    }
    ck_assert_int_eq(nseen, 5);
    ck_assert_int_eq(seen[1], CIA402_SWITCH_ON_DISABLED);
    ck_assert_int_eq(seen[4], CIA402_OP_ENABLED);
}
END_TEST

/* A fault stop as configs/can-sim wires it (enable false and quick-stop true together): the
 * master has written quick stop option code 6 (0x605A), so every frame to the drive carries
 * quick stop 0x0002 for as long as the stop lasts, never disable voltage 0x0000, and the
 * drive stays in Quick stop active holding its position under power. A drive left at the
 * CiA 402 default option 2 would drop to Switch on disabled one SYNC after stopping (power
 * off) and be sent 0x0000 - what the write prevents. */
START_TEST(test_fault_stop_holds)
{
    for (int option = 6; option >= 2; option -= 4) {
        struct rig r;
        rig_init(&r, 2, 2000000);
        rig_run_ms(&r, 80);
        ck_assert_int_eq(r.sim[0].quick_stop_option, 6);   /* written at configuration */
        r.sim[0].quick_stop_option = (int16_t)option;      /* 2: as if it had not been */
        for (int i = 0; i < r.n; i++)
            r.m.node[i].position_cmd_mm = r.m.node[i].position_fb_mm;
        rig_enable(&r, true);
        rig_run_ms(&r, 20);
        ck_assert(canopen_master_all_enabled(&r.m));
        int32_t held = r.sim[0].actual_counts;
        r.ncw = 0;
        for (int i = 0; i < r.n; i++) {
            r.m.node[i].enable = false;
            r.m.node[i].quick_stop = true;
        }
        rig_run_ms(&r, 200);
        if (option == 6) {
            ck_assert_int_eq(r.ncw, 1);
            ck_assert_uint_eq(r.cw_seen[0], CIA402_CW_QUICK_STOP);
            ck_assert_int_eq(r.sim[0].state, CIA402_QUICK_STOP);
            ck_assert_int_eq(r.m.node[0].state, CIA402_QUICK_STOP);
            ck_assert_int_eq(r.sim[0].actual_counts, held);
        } else {
            ck_assert_int_eq(r.sim[0].state, CIA402_SWITCH_ON_DISABLED);
            ck_assert_uint_eq(r.cw_seen[r.ncw - 1], CIA402_CW_DISABLE_VOLTAGE);
        }
    }
}
END_TEST

/* Bad configurations are refused with a message naming the value. */
START_TEST(test_config_errors)
{
    struct canopen_master m;
    char err[200];
    struct canopen_master_cfg cfg = { .n_nodes = 2, .sync_period_ns = 1000000,
                                      .heartbeat_period_ms = 20, .heartbeat_timeout_ms = 100,
                                      .boot_timeout_ms = 500 };
    cfg.node[0] = (struct canopen_node_cfg){ 1, 0, 1000.0, 0.0, 50 };
    cfg.node[1] = (struct canopen_node_cfg){ 1, 1, 1000.0, 0.0, 50 };
    ck_assert_int_eq(canopen_master_init(&m, &cfg, err, sizeof err), CANOPEN_ERR_ARG);
    ck_assert_str_eq(err, "joints 0 and 1 both use NODE_ID 1");
    cfg.node[1].node_id = 128;
    ck_assert_int_eq(canopen_master_init(&m, &cfg, err, sizeof err), CANOPEN_ERR_ARG);
    ck_assert_ptr_nonnull(strstr(err, "NODE_ID 128"));
    cfg.node[1].node_id = 2;
    cfg.heartbeat_timeout_ms = 20;
    ck_assert_int_eq(canopen_master_init(&m, &cfg, err, sizeof err), CANOPEN_ERR_ARG);
    ck_assert_ptr_nonnull(strstr(err, "HEARTBEAT_TIMEOUT"));
    cfg.heartbeat_timeout_ms = 100;
    cfg.sync_period_ns = 1000001;  /* not value * 10^index with value < 256 */
    ck_assert_int_eq(canopen_master_init(&m, &cfg, err, sizeof err), CANOPEN_ERR_ARG);
    ck_assert_ptr_nonnull(strstr(err, "0x60C2"));
    cfg.sync_period_ns = 250000;
    ck_assert_int_eq(canopen_master_init(&m, &cfg, err, sizeof err), CANOPEN_OK);
    ck_assert_uint_eq(m.interp_value, 25);   /* 25 * 10^-5 s */
    ck_assert_int_eq(m.interp_index, -5);
}
END_TEST

/* The suite. */
static Suite *master_suite(void)
{
    Suite *s = suite_create("cia402_master");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, test_startup_configures_nodes);
    tcase_add_test(tc, test_state_machine_to_enabled);
    tcase_add_test(tc, test_follows_commands);
    tcase_add_test(tc, test_sdo_abort);
    tcase_add_test(tc, test_sdo_abort_from_dictionary);
    tcase_add_test(tc, test_sdo_timeout);
    tcase_add_test(tc, test_nmt_boot);
    tcase_add_test(tc, test_bootup_during_config);
    tcase_add_test(tc, test_fault_and_reset);
    tcase_add_test(tc, test_heartbeat_loss);
    tcase_add_test(tc, test_feedback_loss);
    tcase_add_test(tc, test_quick_stop);
    tcase_add_test(tc, test_fault_stop_holds);
    tcase_add_test(tc, test_config_errors);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(master_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
