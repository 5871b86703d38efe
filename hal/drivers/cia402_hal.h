/* cia402_hal.h: the `cia402` HAL component (CiA 402 drives over CAN) and what it shares. */
#ifndef HEXCNC_CIA402_HAL_H
#define HEXCNC_CIA402_HAL_H

#include "hal/hal.h"

/*
 * `loadrt cia402 [count=N]` (N defaults to [KINS]JOINTS, else 6) reads [CAN] and
 * [CAN_NODE_0..N-1] from the INI (see docs/can.md), opens the bus and creates per drive
 *   cia402.N.position-cmd  float in   commanded leg length, mm
 *   cia402.N.position-fb   float out  leg length from the drive's position actual value, mm
 *                                     (position-cmd until the drive has reported once)
 *   cia402.N.enable        bit in     drive to Operation enabled while true
 *   cia402.N.fault         bit out    a latched fault of this drive (message on stderr)
 *   cia402.N.fault-reset   bit in     rising edge: reset the fault, climb back to enabled
 *   cia402.N.quick-stop    bit in     while true: quick stop (0x02) an enabled drive, hold it
 *   cia402.N.state         s32 out    CiA 402 state (enum cia402_state: 5 = Operation enabled)
 *   cia402.N.statusword    u32 out    last statusword 0x6041
 *   cia402.N.emcy-code     u32 out    last EMCY error code (0 after an error reset)
 * and for the bus
 *   cia402.fault-any       bit out    any drive faulted or the bus is off
 *   cia402.all-enabled     bit out    every drive in Operation enabled
 *   cia402.bus-error       bit out    bus-off, or frames dropped or unreadable this period
 *   cia402.bus-off         bit out    the controller reported bus-off
 *   cia402.tx-dropped      u32 out    frames the socket would not take (queue full)
 *   cia402.rx-errors       u32 out    unreadable frames
 *   cia402.error-frames    u32 out    SocketCAN error frames
 *   cia402.sync-count      u32 out    SYNCs sent
 * and the funct cia402.update (never blocks: non-blocking socket, no waits).
 *
 * Objects it registers: CIA402_OBJ_MASTER (struct canopen_master *, for tests and status)
 * and, with [CAN]INTERFACE = sim, CIA402_OBJ_SIM_PEER (int *: the drives' end of the pair,
 * taken by `cia402-sim`; the master closes it at hal_destroy).
 */
#define CIA402_OBJ_MASTER "cia402.master"
#define CIA402_OBJ_SIM_PEER "cia402.sim-peer-fd"

extern const struct hal_comp_type hal_comp_cia402;

#endif
