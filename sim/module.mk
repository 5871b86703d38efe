# sim/: simulated machine parts. The stepgen is a built-in HAL component.
LIB_SRCS += sim/stepgen_core.c sim/stepgen.c sim/sim_home.c sim/sim_spindle.c sim/sim_toolchanger.c \
            sim/sim_probe.c
HAL_COMPS += stepgen sim_home sim_spindle sim_toolchanger sim_probe
TESTS += test_stepgen test_stepgen_hal
# Simulated Modbus drives (libmodbus servers) and their tests.
LIB_SRCS += sim/modbus_sim.c sim/modbus_sim_model.c sim/modbus_sim_hal.c
HAL_COMPS += modbus_sim_server
TESTS += test_modbus test_modbus_faults test_modbus_hal test_modbus_e2e
SCRIPT_TESTS += tests/test_modbus_simclock_load.sh tests/test_modbus_two_process.sh \
                tests/test_modbus_mbpoll.sh
# Simulated CiA 402 drives on CANopen.
LIB_SRCS += sim/cia402_sim.c sim/cia402_sim_od.c sim/cia402_sim_hal.c
HAL_COMPS += cia402_sim

# `make run`: the simulated TMU hexapod on the paper's programs, each started the way a
# machinist starts it (scripts/hexcnc-start): program (10) with the 20 mm tool and program
# (11) with the 10 mm tool, with G141 and with G142, then path 1 with both tools in one
# program, radii from the tool table. Each prints its plan, progress and summary. They run on
# the paper's machine for path 1 (examples/paper/experiment/tmu-path1.ini: F in m/min as the
# paper writes it, the head tilted to the table's normal at B-4 so the compensated wall lies
# on the contour, docs/experiment.md), the simulated TMU hexapod of configs/sim otherwise.
SIM_RUN_PROGRAMS := prog10_g141_d20 prog11_g141_d10 prog10_g142_d20 prog11_g142_d10 \
                    path1_tooltable
SIM_RUN_INI := examples/paper/experiment/tmu-path1.ini
run: all
	@for p in $(SIM_RUN_PROGRAMS); do \
	    echo; echo "== examples/paper/$$p.ngc"; \
	    $(RUN_ENV) sh scripts/hexcnc-start $(SIM_RUN_INI) \
	        examples/paper/$$p.ngc || exit $$?; \
	    mkdir -p $(BUILD)/plots/$$p; \
	    $(RUN_ENV) $(HEXCNC) check --plot $(BUILD)/plots/$$p $(SIM_RUN_INI) \
	        examples/paper/$$p.ngc > $(BUILD)/plots/$$p/check.txt || exit $$?; \
	done; echo; echo "plots (contour vs tool path, legs, deviation): $(BUILD)/plots/*/*.svg"
