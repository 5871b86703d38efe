/* cia402.h: the CiA 402 (IEC 61800-7-201) drive state machine: statusword and controlword. */
#ifndef HEXCNC_CIA402_H
#define HEXCNC_CIA402_H

#include <stdbool.h>
#include <stdint.h>

/* Objects of the drive profile used in cyclic synchronous position mode. */
#define CIA402_OD_CONTROLWORD      0x6040u  /* u16 */
#define CIA402_OD_STATUSWORD       0x6041u  /* u16 */
#define CIA402_OD_MODES_OF_OP      0x6060u  /* i8 */
#define CIA402_OD_MODES_DISPLAY    0x6061u  /* i8 */
#define CIA402_OD_POSITION_ACTUAL  0x6064u  /* i32, counts */
#define CIA402_OD_TARGET_POSITION  0x607Au  /* i32, counts */
#define CIA402_OD_QUICK_STOP_OPTION 0x605Au /* i16: what Quick stop does (CiA 402) */
/* Quick stop option code 6: brake on the quick stop ramp and stay in Quick stop active, under
 * power and holding position. (The CiA 402 default, 2, brakes and then drops to Switch on
 * disabled: power stage off, a hexapod's legs would let the platform go.) */
#define CIA402_QUICK_STOP_HOLD 6
#define CIA402_OD_INTERP_PERIOD    0x60C2u  /* sub 1 value u8, sub 2 index i8: value * 10^index s */
#define CIA402_MODE_CSP            8        /* modes of operation: cyclic synchronous position */

/*
 * The drive's states. The numbers are this project's (the `state` pin shows them); 0 means
 * no statusword has been received yet.
 */
enum cia402_state {
    CIA402_UNKNOWN = 0,
    CIA402_NOT_READY = 1,          /* Not ready to switch on */
    CIA402_SWITCH_ON_DISABLED = 2, /* Switch on disabled */
    CIA402_READY = 3,              /* Ready to switch on */
    CIA402_SWITCHED_ON = 4,        /* Switched on */
    CIA402_OP_ENABLED = 5,         /* Operation enabled: the drive follows the set point */
    CIA402_QUICK_STOP = 6,         /* Quick stop active */
    CIA402_FAULT_REACTION = 7,     /* Fault reaction active */
    CIA402_FAULT = 8,              /* Fault */
};

/*
 * Statusword bits (CiA 402, object 0x6041): 0 ready to switch on, 1 switched on,
 * 2 operation enabled, 3 fault, 4 voltage enabled, 5 quick stop (active low), 6 switch on
 * disabled, 7 warning, 9 remote, 10 target reached, 12 drive follows the command value (CSP).
 */
#define CIA402_SW_READY       0x0001u
#define CIA402_SW_SWITCHED_ON 0x0002u
#define CIA402_SW_OP_ENABLED  0x0004u
#define CIA402_SW_FAULT       0x0008u
#define CIA402_SW_VOLTAGE     0x0010u
#define CIA402_SW_QUICK_STOP  0x0020u
#define CIA402_SW_SO_DISABLED 0x0040u
#define CIA402_SW_REMOTE      0x0200u
#define CIA402_SW_FOLLOWING   0x1000u

/*
 * Controlword commands (CiA 402, object 0x6040): bits 0 switch on, 1 enable
 * voltage, 2 quick stop (active low), 3 enable operation, 7 fault reset (rising edge).
 */
#define CIA402_CW_DISABLE_VOLTAGE 0x0000u  /* transitions 7, 9, 10, 12 */
#define CIA402_CW_QUICK_STOP      0x0002u  /* transitions 7, 10, 11 */
#define CIA402_CW_SHUTDOWN        0x0006u  /* transitions 2, 6, 8 */
#define CIA402_CW_SWITCH_ON       0x0007u  /* transition 3 (and 5: disable operation) */
#define CIA402_CW_ENABLE_OP       0x000Fu  /* transitions 4, 16 */
#define CIA402_CW_FAULT_RESET     0x0080u  /* transition 15, on the rising edge of bit 7 */

/* The state a statusword reports, by the standard masks. */
enum cia402_state cia402_decode(uint16_t statusword);
/* The state's name as the standard writes it ("Operation enabled"). */
const char *cia402_state_name(enum cia402_state s);
/* True in Fault reaction active and Fault. */
bool cia402_is_fault(enum cia402_state s);

/*
 * The controlword that moves a drive one transition towards Operation enabled (enable true)
 * or towards Switch on disabled (enable false). Fault needs a fault reset edge instead, which
 * the caller sequences; here Fault and Fault reaction active answer 0 (bit 7 low).
 */
uint16_t cia402_next_controlword(enum cia402_state s, bool enable);

/* A drive-side command decoded from a controlword (what the simulated drive obeys). */
enum cia402_command {
    CIA402_CMD_DISABLE_VOLTAGE, CIA402_CMD_QUICK_STOP, CIA402_CMD_SHUTDOWN,
    CIA402_CMD_SWITCH_ON, CIA402_CMD_ENABLE_OP,
};
enum cia402_command cia402_command_decode(uint16_t controlword);

#endif
