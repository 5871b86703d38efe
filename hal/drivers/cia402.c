/* cia402.c: CiA 402 statusword decoding and controlword sequencing (pure). */
#include "hal/drivers/cia402.h"

/*
 * Statusword masks, CiA 402 (IEC 61800-7-201) table "state coding":
 *   xxxx xxxx x0xx 0000  Not ready to switch on      (mask 0x4F, value 0x00)
 *   xxxx xxxx x1xx 0000  Switch on disabled          (mask 0x4F, value 0x40)
 *   xxxx xxxx x01x 0001  Ready to switch on          (mask 0x6F, value 0x21)
 *   xxxx xxxx x01x 0011  Switched on                 (mask 0x6F, value 0x23)
 *   xxxx xxxx x01x 0111  Operation enabled           (mask 0x6F, value 0x27)
 *   xxxx xxxx x00x 0111  Quick stop active           (mask 0x6F, value 0x07)
 *   xxxx xxxx x0xx 1111  Fault reaction active       (mask 0x4F, value 0x0F)
 *   xxxx xxxx x0xx 1000  Fault                       (mask 0x4F, value 0x08)
 */
enum cia402_state cia402_decode(uint16_t sw)
{
    switch (sw & 0x4Fu) {
    case 0x00: return CIA402_NOT_READY;
    case 0x40: return CIA402_SWITCH_ON_DISABLED;
    case 0x0F: return CIA402_FAULT_REACTION;
    case 0x08: return CIA402_FAULT;
    default: break;
    }
    switch (sw & 0x6Fu) {
    case 0x21: return CIA402_READY;
    case 0x23: return CIA402_SWITCHED_ON;
    case 0x27: return CIA402_OP_ENABLED;
    case 0x07: return CIA402_QUICK_STOP;
    default: return CIA402_UNKNOWN;  /* a combination the standard does not define */
    }
}

/* The standard's state names, for messages. */
const char *cia402_state_name(enum cia402_state s)
{
    switch (s) {
    case CIA402_NOT_READY: return "Not ready to switch on";
    case CIA402_SWITCH_ON_DISABLED: return "Switch on disabled";
    case CIA402_READY: return "Ready to switch on";
    case CIA402_SWITCHED_ON: return "Switched on";
    case CIA402_OP_ENABLED: return "Operation enabled";
    case CIA402_QUICK_STOP: return "Quick stop active";
    case CIA402_FAULT_REACTION: return "Fault reaction active";
    case CIA402_FAULT: return "Fault";
    default: return "unknown state";
    }
}

/* Fault reaction active counts as a fault: the drive is already stopping on its own. */
bool cia402_is_fault(enum cia402_state s)
{
    return s == CIA402_FAULT || s == CIA402_FAULT_REACTION;
}

/*
 * One step of the device control state machine (CiA 402 figure "state machine"):
 *   Switch on disabled --2 shutdown--> Ready --3 switch on--> Switched on
 *   --4 enable operation--> Operation enabled.
 * Disabling goes 5 (disable operation) / 6 (shutdown) / 7 (disable voltage) back down;
 * a quick stop active drive leaves by 12 (disable voltage) to Switch on disabled.
 */
uint16_t cia402_next_controlword(enum cia402_state s, bool enable)
{
    switch (s) {
    case CIA402_SWITCH_ON_DISABLED:
        return enable ? CIA402_CW_SHUTDOWN : CIA402_CW_DISABLE_VOLTAGE;
    case CIA402_READY:
        return enable ? CIA402_CW_SWITCH_ON : CIA402_CW_DISABLE_VOLTAGE;
    case CIA402_SWITCHED_ON:
        return enable ? CIA402_CW_ENABLE_OP : CIA402_CW_SHUTDOWN;
    case CIA402_OP_ENABLED:
        return enable ? CIA402_CW_ENABLE_OP : CIA402_CW_SHUTDOWN;
    case CIA402_QUICK_STOP:
    case CIA402_NOT_READY:
    case CIA402_FAULT_REACTION:
    case CIA402_FAULT:
    case CIA402_UNKNOWN:
    default:
        return CIA402_CW_DISABLE_VOLTAGE;
    }
}

/*
 * Device control commands by controlword bits 3..0 (CiA 402 table "command coding"), tested
 * from the most to the least dominant: bit 1 low disables voltage whatever else is set,
 * then bit 2 low is quick stop, bit 0 low is shutdown, bit 3 low is switch on.
 */
enum cia402_command cia402_command_decode(uint16_t cw)
{
    if (!(cw & 0x02u))
        return CIA402_CMD_DISABLE_VOLTAGE;
    if (!(cw & 0x04u))
        return CIA402_CMD_QUICK_STOP;
    if (!(cw & 0x01u))
        return CIA402_CMD_SHUTDOWN;
    if (!(cw & 0x08u))
        return CIA402_CMD_SWITCH_ON;
    return CIA402_CMD_ENABLE_OP;
}
