# check/: verification before cutting (hexcnc check), the cutting simulation and the SVG plots.
LIB_SRCS += check/check.c check/check_machine.c check/check_scan.c check/check_sim.c \
            check/check_report.c check/check_plot.c check/svg.c check/cut.c
BENCHES += bench_check
TESTS += test_check test_cut
# `make experiment`: the paper's experiment in the cutting simulation; plots into $(BUILD)/experiment.
LIB_SRCS += check/experiment.c
EXP_BIN := $(BUILD)/check/hexcnc-experiment
$(EXP_BIN): check/experiment_main.c $(LIBDIR)/libhexcnc.a
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(CFLAGS) $(LDFLAGS) -rdynamic $< $(LIBDIR)/libhexcnc.a $(LDLIBS) -o $@
experiment: all $(EXP_BIN)
	@mkdir -p $(BUILD)/experiment
	@$(RUN_ENV) $(EXP_BIN) $(BUILD)/experiment
