# hal/drivers/: the drive components (Modbus, CiA 402 over CAN).
# Modbus drives: pure core (modbus_drive), mailbox + I/O thread (modbus_link).
LIB_SRCS += hal/drivers/modbus_drive.c hal/drivers/modbus_link.c
