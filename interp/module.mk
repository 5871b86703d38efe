# interp/: the RS274/NGC interpreter and the canonical command stream.
LIB_SRCS += interp/canon.c
