# interp/: the RS274/NGC interpreter and the canonical command stream.
LIB_SRCS += interp/canon.c
LIB_SRCS += interp/comp5.c interp/comp5_join.c interp/tooltable.c
TESTS += test_comp5 test_comp5_join test_tooltable
