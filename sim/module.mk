# sim/: simulated machine parts. The stepgen is a built-in HAL component.
LIB_SRCS += sim/stepgen_core.c sim/stepgen.c
HAL_COMPS += stepgen
TESTS += test_stepgen
