# check/: verification before cutting (hexcnc check), the cutting simulation and the SVG plots.
LIB_SRCS += check/check.c check/check_machine.c check/check_scan.c check/check_sim.c \
            check/check_report.c check/check_plot.c check/svg.c check/cut.c
BENCHES += bench_check
TESTS += test_check
