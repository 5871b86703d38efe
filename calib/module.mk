# calib/: kinematic calibration (docs/calibration.md): the fit with Ceres, the pose plan,
# and `make calibration`, the simulated experiment on a perturbed TMU machine.
LIB_SRCS += calib/calib_csv.c calib/calib_fit.c calib/calib_ini.c calib/calib_kins.c calib/calib_plan.c
LIB_CXXSRCS += calib/calib_solve.cpp
TESTS += test_calibrate
# `make calibration`: the simulated experiment; measurements and the fitted INI into
# $(BUILD)/calibration (docs/calibration.md).
CAL_BIN := $(BUILD)/calib/hexcnc-calibration
$(CAL_BIN): calib/calibration_main.c $(LIBDIR)/libhexcnc.a
	@mkdir -p $(@D)
	$(call say,LINK,$@)
	$(Q)$(CC) $(CPPFLAGS) $(CFLAGS) $(LDFLAGS) -rdynamic $< $(LIBDIR)/libhexcnc.a $(LDLIBS) -o $@
.PHONY: calibration
calibration: all $(CAL_BIN)
	@mkdir -p $(BUILD)/calibration
	@$(RUN_ENV) $(CAL_BIN) configs/sim/tmu-hexapod.ini $(BUILD)/calibration --paper
	@rm -f $(BUILD)/calibration/calibrated.ini
	@$(RUN_ENV) $(HEXCNC) calibrate fit configs/sim/tmu-hexapod.ini \
	  $(BUILD)/calibration/measurements.csv -o $(BUILD)/calibration/calibrated.ini \
	  > $(BUILD)/calibration/fit.txt && tail -n 45 $(BUILD)/calibration/fit.txt
SCRIPT_TESTS += tests/calibrate_cli.sh
