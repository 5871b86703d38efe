# sim/: simulated machine parts. The stepgen is a built-in HAL component.
LIB_SRCS += sim/stepgen_core.c sim/stepgen.c
HAL_COMPS += stepgen
TESTS += test_stepgen test_stepgen_hal
# Simulated Modbus drives (libmodbus servers) and their tests.
LIB_SRCS += sim/modbus_sim.c sim/modbus_sim_model.c sim/modbus_sim_hal.c
HAL_COMPS += modbus_sim_server
TESTS += test_modbus test_modbus_faults test_modbus_hal test_modbus_e2e
# Simulated CiA 402 drives on CANopen.
LIB_SRCS += sim/cia402_sim.c sim/cia402_sim_od.c sim/cia402_sim_hal.c
HAL_COMPS += cia402_sim
