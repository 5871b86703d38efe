# hal/drivers/: the drive components (Modbus, CiA 402 over CAN).
# Modbus drives: pure core (modbus_drive), mailbox + I/O thread (modbus_link).
LIB_SRCS += hal/drivers/modbus_drive.c hal/drivers/modbus_link.c hal/drivers/modbus_cfg.c \
            hal/drivers/modbus_hal.c
HAL_COMPS += modbus
BENCHES += bench_modbus
SCRIPT_TESTS += tests/test_modbus_cli.sh
# CiA 402 over CAN: CiA 301 codec, master core, SocketCAN transport, bus-load arithmetic.
LIB_SRCS += hal/drivers/canopen.c hal/drivers/canopen_config.c hal/drivers/canopen_master.c \
            hal/drivers/cia402.c hal/drivers/can_bus.c hal/drivers/can_load.c hal/drivers/cia402_hal.c
HAL_COMPS += cia402
TESTS += test_can_proto
TESTS += test_cia402_master
TESTS += test_can_bus
TESTS += test_can_hal
BENCHES += bench_can
TESTS += test_can_e2e
SCRIPT_TESTS += tests/can_unix.sh
