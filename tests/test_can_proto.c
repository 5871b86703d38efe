/* test_can_proto.c: CiA 301 / CiA 402 encodings, PDO round trip, bus-load arithmetic. */
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hal/drivers/can_load.h"
#include "hal/drivers/canopen.h"
#include "hal/drivers/canopen_master.h"
#include "hal/drivers/cia402.h"

/* NMT, SYNC, heartbeat and EMCY frames carry the COB-IDs and bytes of CiA 301. */
START_TEST(test_frames)
{
    struct can_frame f;
    canopen_nmt(&f, CANOPEN_NMT_START, 5);
    ck_assert_uint_eq(f.can_id, 0x000);
    ck_assert_uint_eq(f.can_dlc, 2);
    ck_assert_uint_eq(f.data[0], 0x01);
    ck_assert_uint_eq(f.data[1], 5);
    canopen_nmt(&f, CANOPEN_NMT_RESET_COMM, 0);
    ck_assert_uint_eq(f.data[0], 0x82);
    canopen_sync(&f);
    ck_assert_uint_eq(f.can_id, 0x080);
    ck_assert_uint_eq(f.can_dlc, 0);
    canopen_heartbeat(&f, 7, CANOPEN_STATE_OPERATIONAL);
    ck_assert_uint_eq(f.can_id, 0x707);
    ck_assert_uint_eq(f.data[0], 0x05);
    canopen_emcy(&f, 3, 0x2310, 0x03);
    ck_assert_uint_eq(f.can_id, 0x083);
    ck_assert_uint_eq(f.data[0], 0x10);
    ck_assert_uint_eq(f.data[1], 0x23);
    ck_assert_uint_eq(f.data[2], 0x03);
    int node;
    ck_assert_int_eq(canopen_classify(&f, &node), CANOPEN_KIND_EMCY);
    ck_assert_int_eq(node, 3);
    canopen_sync(&f);
    ck_assert_int_eq(canopen_classify(&f, &node), CANOPEN_KIND_SYNC);
    f.can_id = 0x185;
    ck_assert_int_eq(canopen_classify(&f, &node), CANOPEN_KIND_TPDO1);
    ck_assert_int_eq(node, 5);
    f.can_id = 0x205 | CAN_EFF_FLAG;  /* extended frames are not CANopen's */
    ck_assert_int_eq(canopen_classify(&f, &node), CANOPEN_KIND_OTHER);
}
END_TEST

/* Expedited SDO download: command bytes 0x2F / 0x2B / 0x23, index LE, data LE. */
START_TEST(test_sdo_write_encoding)
{
    struct can_frame f;
    canopen_sdo_write(&f, 2, 0x6060, 0, 8, 1);
    ck_assert_uint_eq(f.can_id, 0x602);
    ck_assert_uint_eq(f.can_dlc, 8);
    const uint8_t want1[8] = { 0x2F, 0x60, 0x60, 0x00, 0x08, 0, 0, 0 };
    ck_assert_mem_eq(f.data, want1, 8);
    canopen_sdo_write(&f, 2, 0x1017, 0, 20, 2);
    const uint8_t want2[8] = { 0x2B, 0x17, 0x10, 0x00, 20, 0, 0, 0 };
    ck_assert_mem_eq(f.data, want2, 8);
    canopen_sdo_write(&f, 2, 0x1600, 1, 0x60400010, 4);
    const uint8_t want4[8] = { 0x23, 0x00, 0x16, 0x01, 0x10, 0x00, 0x40, 0x60 };
    ck_assert_mem_eq(f.data, want4, 8);
    struct canopen_sdo s;
    ck_assert(canopen_sdo_decode(&f, &s));
    ck_assert(canopen_sdo_is_expedited_write(&s));
    ck_assert_int_eq(s.size, 4);
    ck_assert_uint_eq(s.index, 0x1600);
    ck_assert_uint_eq(s.sub, 1);
    ck_assert_uint_eq(s.value, 0x60400010u);
    /* a 1-byte write of -3 (0x60C2:02) keeps only the low byte */
    canopen_sdo_write(&f, 2, 0x60C2, 2, (uint32_t)-3, 1);
    ck_assert(canopen_sdo_decode(&f, &s));
    ck_assert_int_eq(s.size, 1);
    ck_assert_uint_eq(s.value, 0xFDu);
}
END_TEST

/* Answers: the download response 0x60 and the abort 0x80 with its code in bytes 4..7. */
START_TEST(test_sdo_answers)
{
    struct can_frame f;
    struct canopen_sdo s;
    canopen_sdo_write_ok(&f, 9, 0x6060, 0);
    ck_assert_uint_eq(f.can_id, 0x589);
    ck_assert(canopen_sdo_decode(&f, &s));
    ck_assert_uint_eq(s.cmd, 0x60);
    canopen_sdo_abort(&f, CANOPEN_COB_SDO_TX, 9, 0x6060, 0, 0x06090030u);
    const uint8_t want[8] = { 0x80, 0x60, 0x60, 0x00, 0x30, 0x00, 0x09, 0x06 };
    ck_assert_mem_eq(f.data, want, 8);
    ck_assert(canopen_sdo_decode(&f, &s));
    ck_assert_uint_eq(s.value, 0x06090030u);
    ck_assert_str_eq(canopen_abort_text(0x06090030u), "value range of parameter exceeded");
    ck_assert_str_eq(canopen_abort_text(0x06020000u),
                     "object does not exist in the object dictionary");
    ck_assert_str_eq(canopen_abort_text(0x12345678u), "unknown abort code");
    f.can_dlc = 7;
    ck_assert(!canopen_sdo_decode(&f, &s));
}
END_TEST

/* EMCY code classes: the most specific entry of CiA 301's table. */
START_TEST(test_emcy_text)
{
    ck_assert_str_eq(canopen_emcy_text(0x2310), "current, device output side (motor over-current)");
    ck_assert_str_eq(canopen_emcy_text(0x4210), "device temperature");
    ck_assert_str_eq(canopen_emcy_text(0x8130), "life guard or heartbeat error");
    ck_assert_str_eq(canopen_emcy_text(0x8611), "monitoring (e.g. following error)");
    ck_assert_str_eq(canopen_emcy_text(0x0000), "error reset or no error");
    ck_assert_str_eq(canopen_emcy_text(0xFF01), "device specific");
}
END_TEST

/* Every state of CiA 402's coding table, with the don't-care bits set to both values. */
START_TEST(test_statusword_decode)
{
    const struct { uint16_t sw; enum cia402_state st; } cases[] = {
        { 0x0000, CIA402_NOT_READY }, { 0x0020, CIA402_NOT_READY },
        { 0x0040, CIA402_SWITCH_ON_DISABLED }, { 0x0260, CIA402_SWITCH_ON_DISABLED },
        { 0x0021, CIA402_READY }, { 0x0231, CIA402_READY },
        { 0x0023, CIA402_SWITCHED_ON }, { 0x0233, CIA402_SWITCHED_ON },
        { 0x0027, CIA402_OP_ENABLED }, { 0x1637, CIA402_OP_ENABLED },
        { 0x0007, CIA402_QUICK_STOP }, { 0x0017, CIA402_QUICK_STOP },
        { 0x000F, CIA402_FAULT_REACTION }, { 0x003F, CIA402_FAULT_REACTION },
        { 0x0008, CIA402_FAULT }, { 0x0238, CIA402_FAULT },
        { 0x0001, CIA402_UNKNOWN },  /* ready bit with quick stop low: not a defined state */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        ck_assert_msg(cia402_decode(cases[i].sw) == cases[i].st, "statusword 0x%04X",
                      cases[i].sw);
    ck_assert_str_eq(cia402_state_name(CIA402_OP_ENABLED), "Operation enabled");
}
END_TEST

/* The controlword ladder up to Operation enabled and the drive-side command decoding. */
START_TEST(test_controlword)
{
    ck_assert_uint_eq(cia402_next_controlword(CIA402_SWITCH_ON_DISABLED, true), 0x06);
    ck_assert_uint_eq(cia402_next_controlword(CIA402_READY, true), 0x07);
    ck_assert_uint_eq(cia402_next_controlword(CIA402_SWITCHED_ON, true), 0x0F);
    ck_assert_uint_eq(cia402_next_controlword(CIA402_OP_ENABLED, true), 0x0F);
    ck_assert_uint_eq(cia402_next_controlword(CIA402_OP_ENABLED, false), 0x06);
    ck_assert_uint_eq(cia402_next_controlword(CIA402_FAULT, true), 0x00);
    ck_assert_int_eq(cia402_command_decode(0x06), CIA402_CMD_SHUTDOWN);
    ck_assert_int_eq(cia402_command_decode(0x0E), CIA402_CMD_SHUTDOWN);
    ck_assert_int_eq(cia402_command_decode(0x07), CIA402_CMD_SWITCH_ON);
    ck_assert_int_eq(cia402_command_decode(0x0F), CIA402_CMD_ENABLE_OP);
    ck_assert_int_eq(cia402_command_decode(0x02), CIA402_CMD_QUICK_STOP);
    ck_assert_int_eq(cia402_command_decode(0x0B), CIA402_CMD_QUICK_STOP);
    ck_assert_int_eq(cia402_command_decode(0x0D), CIA402_CMD_DISABLE_VOLTAGE);
    ck_assert_int_eq(cia402_command_decode(0x80), CIA402_CMD_DISABLE_VOLTAGE);
}
END_TEST

/* PDO payload: little-endian word then position; mm <-> counts with offset and sign. */
START_TEST(test_pdo_round_trip)
{
    struct canopen_node_cfg c = { .node_id = 1, .counts_per_mm = 1000.0, .offset_mm = 600.0 };
    int32_t counts;
    ck_assert(canopen_mm_to_counts(&c, 612.3456, &counts));
    ck_assert_int_eq(counts, 12346);  /* 12.3456 mm at 1 um per count, rounded */
    struct can_frame f;
    canopen_pdo_pack(&f, 0x201, 0x000F, counts);
    const uint8_t want[6] = { 0x0F, 0x00, 0x3A, 0x30, 0x00, 0x00 };
    ck_assert_uint_eq(f.can_dlc, 6);
    ck_assert_mem_eq(f.data, want, 6);
    ck_assert(canopen_mm_to_counts(&c, 590.0, &counts));
    canopen_pdo_pack(&f, 0x201, 0x1237, counts);
    const uint8_t want_neg[6] = { 0x37, 0x12, 0xF0, 0xD8, 0xFF, 0xFF };  /* -10000 */
    ck_assert_mem_eq(f.data, want_neg, 6);
    uint16_t w;
    int32_t p;
    ck_assert(canopen_pdo_unpack(&f, &w, &p));
    ck_assert_uint_eq(w, 0x1237);
    ck_assert_int_eq(p, -10000);
    ck_assert_double_eq_tol(canopen_counts_to_mm(&c, p), 590.0, 1e-12);
    struct canopen_node_cfg rev = { .node_id = 1, .counts_per_mm = -400.0, .offset_mm = 0.0 };
    ck_assert(canopen_mm_to_counts(&rev, 1.0, &counts));
    ck_assert_int_eq(counts, -400);
    ck_assert(!canopen_mm_to_counts(&c, 1e7, &counts));  /* beyond 2^31 counts */
    ck_assert(!canopen_mm_to_counts(&c, NAN, &counts));
    f.can_dlc = 5;
    ck_assert(!canopen_pdo_unpack(&f, &w, &p));
}
END_TEST

/* Frame sizes of ISO 11898-1 with and without worst-case stuffing. */
START_TEST(test_frame_bits)
{
    ck_assert_int_eq(can_frame_bits(8, false), 111);       /* 44 + 64 + 3 */
    ck_assert_int_eq(can_frame_bits(8, true), 111 + 24);   /* floor(97 / 4) */
    ck_assert_int_eq(can_frame_bits(6, true), 95 + 20);    /* floor(81 / 4) */
    ck_assert_int_eq(can_frame_bits(0, true), 47 + 8);     /* SYNC: floor(33 / 4) */
    ck_assert_int_eq(can_frame_bits(1, true), 55 + 10);    /* heartbeat */
}
END_TEST

/* Six drives: 1 kHz does not fit on 1 Mbit/s, 500 Hz fits with 6-byte PDOs, 250 Hz easily. */
START_TEST(test_bus_load)
{
    double l8 = can_bus_load(1, 0, 1000, 1e6) + can_bus_load(12, 8, 1000, 1e6);
    ck_assert_double_eq_tol(l8, (55 + 12 * 135) / 1000.0, 1e-12);  /* 167.5 % */
    ck_assert(l8 > 1.0);
    double l6 = can_csp_load(6, 6, 6, 1000, 0, 1e6);
    ck_assert_double_eq_tol(l6, (55 + 12 * 115) / 1000.0, 1e-12);  /* 143.5 % */
    double l6_500 = can_csp_load(6, 6, 6, 500, 50, 1e6);
    ck_assert_double_eq_tol(l6_500, (55 + 12 * 115) * 500 / 1e6 + 6 * 65 * 50 / 1e6, 1e-12);
    ck_assert(l6_500 < 0.80);
    ck_assert(can_csp_load(6, 8, 8, 250, 50, 1e6) < 0.5);
    ck_assert_double_eq(can_bus_load(3, 8, 1000, 0), 0.0);
}
END_TEST

/* The suite. */
static Suite *can_proto_suite(void)
{
    Suite *s = suite_create("can_proto");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, test_frames);
    tcase_add_test(tc, test_sdo_write_encoding);
    tcase_add_test(tc, test_sdo_answers);
    tcase_add_test(tc, test_emcy_text);
    tcase_add_test(tc, test_statusword_decode);
    tcase_add_test(tc, test_controlword);
    tcase_add_test(tc, test_pdo_round_trip);
    tcase_add_test(tc, test_frame_bits);
    tcase_add_test(tc, test_bus_load);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(can_proto_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
