# check/: verification before cutting (hexcnc check), the cutting simulation and the SVG plots.
LIB_SRCS += check/check.c check/check_machine.c check/check_scan.c check/check_sim.c check/check_defer.c check/check_stream.c \
            check/check_report.c check/check_plot.c check/svg.c check/cut.c
BENCHES += bench_check bench_check_dense bench_plan_dense
TESTS += test_check test_cut test_check_runner test_tcp test_check_stream test_check_defer
# `make experiment`: the paper's experiment in the cutting simulation; plots into $(BUILD)/experiment.
LIB_SRCS += check/experiment.c
EXP_BIN := $(BUILD)/check/hexcnc-experiment
$(EXP_BIN): check/experiment_main.c $(LIBDIR)/libhexcnc.a
	@mkdir -p $(@D)
	$(call say,LINK,$@)
	$(Q)$(CC) $(CPPFLAGS) $(CFLAGS) $(LDFLAGS) -rdynamic $< $(LIBDIR)/libhexcnc.a $(LDLIBS) -o $@
EXP_PROGS := run1_g141:1 run2_g141:1 run3_g141:2 run4_g141:2 run1_g142:1
experiment: all $(EXP_BIN)
	@mkdir -p $(BUILD)/experiment
	@$(RUN_ENV) $(EXP_BIN) $(BUILD)/experiment
	@for r in $(EXP_PROGS); do n=$${r%%:*}; p=$${r##*:}; mkdir -p $(BUILD)/experiment/$$n; \
	  $(RUN_ENV) $(HEXCNC) check --plot $(BUILD)/experiment/$$n \
	    examples/paper/experiment/tmu-path$$p.ini examples/paper/experiment/$$n.ngc \
	    > $(BUILD)/experiment/$$n/check.txt || { cat $(BUILD)/experiment/$$n/check.txt; exit 1; }; \
	done; echo "hexcnc check of each program (table and plots): $(BUILD)/experiment/run*/"
