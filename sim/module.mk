# sim/: simulated machine parts. The stepgen is a built-in HAL component.
LIB_SRCS += sim/stepgen.c
HAL_COMPS += stepgen
