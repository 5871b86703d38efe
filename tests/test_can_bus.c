/* test_can_bus.c: the frame transport: socketpair read/write path end to end, real-interface errors. */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

#include "hal/drivers/can_bus.h"
#include "hal/drivers/canopen_master.h"
#include "hal/drivers/cia402_hal.h"
#include "hal/hal.h"
#include "sim/cia402_sim.h"

/* Frames keep their boundaries and bytes through the pair, both ways, with both the
 * per-frame and the batched calls; an empty socket returns at once with nothing. */
START_TEST(test_pair_frames)
{
    struct can_bus b;
    char err[200];
    ck_assert_int_eq(can_bus_open(&b, CAN_BUS_SIM, err, sizeof err), CAN_BUS_OK);
    ck_assert_int_ge(b.sim_peer_fd, 0);
    struct can_frame out[3], in[8];
    canopen_sync(&out[0]);
    canopen_pdo_pack(&out[1], 0x203, 0x000F, -123456);
    canopen_sdo_write(&out[2], 3, 0x6060, 0, 8, 1);
    ck_assert_int_eq(can_bus_send(&b, out, 3), 3);
    for (int i = 0; i < 3; i++) {
        ck_assert_int_eq(can_fd_read(b.sim_peer_fd, &in[i]), 1);
        ck_assert_uint_eq(in[i].can_id, out[i].can_id);
        ck_assert_uint_eq(in[i].can_dlc, out[i].can_dlc);
        ck_assert_mem_eq(in[i].data, out[i].data, 8);
    }
    ck_assert_int_eq(can_fd_read(b.sim_peer_fd, &in[0]), 0);  /* empty: no wait */
    /* the other way, read batched */
    for (int i = 0; i < 3; i++)
        ck_assert_int_eq(can_fd_write(b.sim_peer_fd, &out[i]), 1);
    ck_assert_int_eq(can_bus_recv_batch(&b, in, 8), 3);
    ck_assert_uint_eq(in[1].can_id, 0x203);
    uint16_t w;
    int32_t p;
    ck_assert(canopen_pdo_unpack(&in[1], &w, &p));
    ck_assert_int_eq(p, -123456);
    ck_assert_int_eq(can_bus_recv(&b, in, 8), 0);
    ck_assert_int_eq(can_bus_recv_batch(&b, in, 8), 0);
    /* batched send, per-frame receive on the far end */
    ck_assert_int_eq(can_bus_send_batch(&b, out, 3), 3);
    ck_assert_int_eq(can_fd_read(b.sim_peer_fd, &in[0]), 1);
    ck_assert_uint_eq(in[0].can_id, 0x080);
    ck_assert_uint_eq(b.tx_frames, 6);
    ck_assert_uint_eq(b.rx_frames, 3);
    can_bus_close(&b);
}
END_TEST

/* A message that is not one frame is counted and skipped; error frames are counted, their
 * bus-off flag kept, and never handed to the protocol. */
START_TEST(test_odd_messages)
{
    struct can_bus b;
    char err[200];
    ck_assert_int_eq(can_bus_open(&b, CAN_BUS_SIM, err, sizeof err), CAN_BUS_OK);
    char junk[5] = "abcd";
    ck_assert_int_eq(write(b.sim_peer_fd, junk, sizeof junk), (ssize_t)sizeof junk);
    struct can_frame e, f, in[4];
    memset(&e, 0, sizeof e);
    e.can_id = CAN_ERR_FLAG | 0x040u;  /* CAN_ERR_BUSOFF */
    e.can_dlc = 8;
    canopen_heartbeat(&f, 2, CANOPEN_STATE_OPERATIONAL);
    ck_assert_int_eq(can_fd_write(b.sim_peer_fd, &e), 1);
    ck_assert_int_eq(can_fd_write(b.sim_peer_fd, &f), 1);
    ck_assert_int_eq(can_bus_recv(&b, in, 4), 1);
    ck_assert_uint_eq(in[0].can_id, 0x702);
    ck_assert_uint_eq(b.rx_errors, 1);
    ck_assert_uint_eq(b.err_frames, 1);
    ck_assert(b.bus_off);
    can_bus_close(&b);
}
END_TEST

/* A full queue drops frames instead of blocking the servo thread. */
START_TEST(test_full_queue_never_blocks)
{
    struct can_bus b;
    char err[200];
    ck_assert_int_eq(can_bus_open(&b, CAN_BUS_SIM, err, sizeof err), CAN_BUS_OK);
    struct can_frame f[64];
    for (int i = 0; i < 64; i++)
        canopen_sync(&f[i]);
    int total = 0, r;
    for (int round = 0; round < 10000 && (r = can_bus_send(&b, f, 64)) == 64; round++)
        total += r;
    ck_assert_int_gt(total, 0);
    ck_assert_uint_gt(b.tx_dropped, 0);  /* the queue filled up and the call came back */
    can_bus_close(&b);
}
END_TEST

/* The master core and three simulated drives talk through the pair with the same calls
 * the HAL component uses: configuration, enable, a commanded move. */
START_TEST(test_master_over_pair)
{
    struct can_bus b;
    char err[200];
    ck_assert_int_eq(can_bus_open(&b, CAN_BUS_SIM, err, sizeof err), CAN_BUS_OK);
    struct canopen_master m;
    struct canopen_master_cfg cfg = { .n_nodes = 3, .sync_period_ns = 1000000,
                                      .heartbeat_period_ms = 10, .heartbeat_timeout_ms = 50,
                                      .boot_timeout_ms = 200 };
    struct cia402_sim sim[3];
    for (int i = 0; i < 3; i++) {
        cfg.node[i] = (struct canopen_node_cfg){ i + 10, i, 500.0, 700.0, 50 };
        struct cia402_sim_cfg sc = { .node_id = i + 10 };
        cia402_sim_init(&sim[i], &sc);
    }
    ck_assert_int_eq(canopen_master_init(&m, &cfg, err, sizeof err), CANOPEN_OK);
    struct can_frame buf[64], ans[CIA402_SIM_MAX_OUT];
    int64_t now = 0;
    for (int t = 0; t < 300; t++, now += 1000000) {
        int n = can_bus_recv_batch(&b, buf, 64);
        for (int i = 0; i < n; i++)
            canopen_master_rx(&m, &buf[i], now);
        for (int i = 0; i < 3; i++) {
            m.node[i].enable = t > 60;
            m.node[i].position_cmd_mm = t > 100 ? 700.0 + 0.01 * (t - 100) : 700.0;
        }
        n = canopen_master_step(&m, now, buf, 64);
        ck_assert_int_eq(can_bus_send(&b, buf, n), n);
        struct can_frame in;
        while (can_fd_read(b.sim_peer_fd, &in) == 1)
            for (int s = 0; s < 3; s++) {
                int k = cia402_sim_rx(&sim[s], &in, now, ans, CIA402_SIM_MAX_OUT);
                for (int j = 0; j < k; j++)
                    ck_assert_int_eq(can_fd_write(b.sim_peer_fd, &ans[j]), 1);
            }
        for (int s = 0; s < 3; s++) {
            int k = cia402_sim_step(&sim[s], now, ans, CIA402_SIM_MAX_OUT);
            for (int j = 0; j < k; j++)
                ck_assert_int_eq(can_fd_write(b.sim_peer_fd, &ans[j]), 1);
        }
    }
    ck_assert(canopen_master_all_enabled(&m));
    for (int i = 0; i < 3; i++) {
        ck_assert(!m.node[i].fault);
        /* commanded 700 + 0.01 * 199 at the last step; the feedback is two periods behind */
        ck_assert_double_eq_tol(m.node[i].position_fb_mm, 700.0 + 0.01 * 197, 0.0011);
        ck_assert_int_eq(sim[i].actual_counts, (int32_t)(0.01 * 198 * 500.0 + 0.5));
    }
    ck_assert_uint_eq(b.tx_dropped, 0);
    ck_assert_uint_eq(b.rx_errors, 0);
    can_bus_close(&b);
}
END_TEST

/* Opening a real interface fails here (no SocketCAN, or no such interface) with a message
 * that names it and says what to do; the HAL component adds the INI file and key. */
START_TEST(test_real_interface_error)
{
    struct can_bus b;
    char err[300];
    int st = can_bus_open(&b, "hexcnccan9", err, sizeof err);
    ck_assert(st == CAN_BUS_ERR_NO_SOCKETCAN || st == CAN_BUS_ERR_NO_IFACE);
    ck_assert_ptr_nonnull(strstr(err, "CAN interface 'hexcnccan9'"));
    if (st == CAN_BUS_ERR_NO_SOCKETCAN)
        ck_assert_ptr_nonnull(strstr(err, "no SocketCAN"));
    ck_assert_int_eq(b.fd, -1);

    char path[] = "/tmp/test_can_bus_XXXXXX";
    int fd = mkstemp(path);
    ck_assert_int_ge(fd, 0);
    const char ini[] = "[KINS]\nJOINTS = 1\n[CAN]\nINTERFACE = hexcnccan9\n"
                       "[CAN_NODE_0]\nNODE_ID = 1\nCOUNTS_PER_MM = 1000\n";
    ck_assert_int_eq(write(fd, ini, sizeof ini - 1), (ssize_t)(sizeof ini - 1));
    close(fd);
    struct hal *h = hal_create();
    ck_assert_int_eq(hal_load_ini(h, path), HAL_OK);
    ck_assert_int_ne(hal_cmd(h, "loadrt cia402", "test.hal", 3, stdout), HAL_OK);
    const char *msg = hal_last_error(h);
    ck_assert_ptr_nonnull(strstr(msg, path));
    ck_assert_ptr_nonnull(strstr(msg, "[CAN]INTERFACE = hexcnccan9"));
    ck_assert_ptr_nonnull(strstr(msg, "CAN interface 'hexcnccan9'"));
    hal_destroy(h);
    unlink(path);
}
END_TEST

/* The other end of the pair closes: reads end at once (a zero-length message is the end of
 * the stream; recvmmsg used to return it forever and the servo thread spun), writes fail
 * without SIGPIPE, and the bus says the peer is gone. */
START_TEST(test_peer_closed)
{
    for (int batched = 0; batched <= 1; batched++) {
        struct can_bus b;
        char err[200];
        ck_assert_int_eq(can_bus_open(&b, CAN_BUS_SIM, err, sizeof err), CAN_BUS_OK);
        struct can_frame f[8];
        memset(f, 0, sizeof f);
        close(b.sim_peer_fd);
        b.sim_peer_fd = -1;
        int n = batched ? can_bus_recv_batch(&b, f, 8) : can_bus_recv(&b, f, 8);
        ck_assert_int_eq(n, 0);
        ck_assert(b.peer_closed);
        ck_assert_int_eq(batched ? can_bus_send_batch(&b, f, 3) : can_bus_send(&b, f, 3), 0);
        ck_assert_uint_eq(b.tx_dropped, 3);
        can_bus_close(&b);
    }
    struct can_bus b;  /* sending first finds it too */
    char err[200];
    ck_assert_int_eq(can_bus_open(&b, CAN_BUS_SIM, err, sizeof err), CAN_BUS_OK);
    close(b.sim_peer_fd);
    b.sim_peer_fd = -1;
    struct can_frame f = { .can_id = 0x80 };
    ck_assert_int_eq(can_bus_send_batch(&b, &f, 1), 0);
    ck_assert(b.peer_closed);
    can_bus_close(&b);
}
END_TEST

/* The HAL component on a closed pair: one fault message naming the bus, fault-any, every
 * drive faulted, and the servo period returns (within 2 s of wall time for 50 periods). */
START_TEST(test_cia402_peer_closed)
{
    char path[] = "/tmp/test_can_bus_XXXXXX";
    int fd = mkstemp(path);
    ck_assert_int_ge(fd, 0);
    const char ini[] = "[KINS]\nJOINTS = 2\n[CAN]\nINTERFACE = sim\n"
                       "[CAN_NODE_0]\nNODE_ID = 1\nCOUNTS_PER_MM = 1000\n"
                       "[CAN_NODE_1]\nNODE_ID = 2\nCOUNTS_PER_MM = 1000\n";
    ck_assert_int_eq(write(fd, ini, sizeof ini - 1), (ssize_t)(sizeof ini - 1));
    close(fd);
    struct hal *h = hal_create();
    ck_assert_int_eq(hal_load_ini(h, path), HAL_OK);
    hal_set_sim_clock(h, true);
    const char *cmds[] = { "newthread servo-thread 1000000", "loadrt cia402",
                           "loadrt cia402-sim", "addf cia402.update servo-thread",
                           "addf cia402-sim.update servo-thread" };
    for (size_t i = 0; i < sizeof cmds / sizeof cmds[0]; i++)
        ck_assert_msg(hal_cmd(h, cmds[i], "test.hal", (int)i + 1, stdout) == HAL_OK, "%s",
                      hal_last_error(h));
    ck_assert_int_eq(hal_start(h), HAL_OK);
    ck_assert_int_eq(hal_sim_advance(h, 100 * 1000000L), HAL_OK);
    const struct canopen_master *m = hal_get_object(h, CIA402_OBJ_MASTER);
    ck_assert(m->node[0].phase == CANOPEN_PHASE_RUN && m->node[1].phase == CANOPEN_PHASE_RUN);
    int *peer = hal_get_object(h, CIA402_OBJ_SIM_PEER);
    shutdown(*peer, SHUT_RDWR);  /* the drives' end goes away (the component still owns it) */
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    ck_assert_int_eq(hal_sim_advance(h, 50 * 1000000L), HAL_OK);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    ck_assert_int_lt(t1.tv_sec - t0.tv_sec, 2);
    char any[16];
    ck_assert_int_eq(hal_getp(h, "cia402.fault-any", any, sizeof any), HAL_OK);
    ck_assert_msg(strcmp(any, "TRUE") == 0 || strcmp(any, "true") == 0 || strcmp(any, "1") == 0,
                  "%s", any);
    ck_assert(m->node[0].fault && m->node[1].fault);
    ck_assert_int_eq(m->node[1].fault_status, CANOPEN_ERR_BUS_LOST);
    struct hal_msg msg;
    int faults = 0;
    while (hal_msg_take(h, &msg))
        if (msg.severity == HAL_MSG_FAULT) {
            faults++;
            ck_assert_str_eq(msg.source, "cia402");
            ck_assert_msg(strstr(msg.text, "CAN bus sim: the other end closed the connection")
                          != NULL, "%s", msg.text);
        }
    ck_assert_int_eq(faults, 1);
    hal_destroy(h);
    unlink(path);
}
END_TEST

/* [CAN]INTERFACE = unix:PATH connects to a SEQPACKET listener and carries frames both ways;
 * a path nobody listens on is refused with the path and the command that would serve it. */
START_TEST(test_unix_interface)
{
    char dir[] = "/tmp/test_can_unix_XXXXXX", path[96], name[160];
    ck_assert_ptr_nonnull(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/can.sock", dir);
    snprintf(name, sizeof name, "unix:%s", path);
    struct can_bus b;
    char err[300];
    ck_assert_int_eq(can_bus_open(&b, name, err, sizeof err), CAN_BUS_ERR_SOCKET);
    ck_assert_ptr_nonnull(strstr(err, path));
    ck_assert_ptr_nonnull(strstr(err, "hexcnc can_sim"));
    int lfd = socket(AF_UNIX, SOCK_SEQPACKET, 0);
    struct sockaddr_un sa = { .sun_family = AF_UNIX };
    snprintf(sa.sun_path, sizeof sa.sun_path, "%s", path);
    ck_assert_int_eq(bind(lfd, (struct sockaddr *)&sa, sizeof sa), 0);
    ck_assert_int_eq(listen(lfd, 1), 0);
    ck_assert_msg(can_bus_open(&b, name, err, sizeof err) == CAN_BUS_OK, "%s", err);
    int peer = accept(lfd, NULL, NULL);
    ck_assert_int_ge(peer, 0);
    struct can_frame out = { .can_id = 0x601, .can_dlc = 8, .data = { 0x2B, 0x17, 0x10 } }, in;
    ck_assert_int_eq(can_bus_send_batch(&b, &out, 1), 1);
    ck_assert_int_eq(can_fd_read(peer, &in), 1);
    ck_assert_uint_eq(in.can_id, 0x601);
    ck_assert_int_eq(memcmp(in.data, out.data, 8), 0);
    struct can_frame ans = { .can_id = 0x581, .can_dlc = 8, .data = { 0x60 } }, got[4];
    ck_assert_int_eq(can_fd_write(peer, &ans), 1);
    ck_assert_int_eq(can_bus_recv_batch(&b, got, 4), 1);
    ck_assert_uint_eq(got[0].can_id, 0x581);
    close(peer);
    ck_assert_int_eq(can_bus_recv_batch(&b, got, 4), 0);
    ck_assert(b.peer_closed);
    can_bus_close(&b);
    close(lfd);
    unlink(path);
    rmdir(dir);
}
END_TEST

/* The suite. */
static Suite *can_bus_suite(void)
{
    Suite *s = suite_create("can_bus");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, test_pair_frames);
    tcase_add_test(tc, test_odd_messages);
    tcase_add_test(tc, test_full_queue_never_blocks);
    tcase_add_test(tc, test_master_over_pair);
    tcase_add_test(tc, test_real_interface_error);
    tcase_add_test(tc, test_peer_closed);
    tcase_add_test(tc, test_cia402_peer_closed);
    tcase_add_test(tc, test_unix_interface);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(can_bus_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
