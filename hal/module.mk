# hal/: the component-graph runtime, the HAL command language, the INI reader, and the
# generic built-in components.
LIB_SRCS += hal/hal_core.c hal/hal_map.c hal/hal_pin.c hal/hal_value.c hal/hal_funct.c hal/hal_rt.c \
            hal/hal_ini.c hal/hal_load.c hal/hal_cmd.c hal/hal_file.c hal/hal_show.c \
            hal/hal_msg.c hal/ring.c

# Built-in generic components (hal/components/motion.c adds itself elsewhere).
LIB_SRCS += hal/components/kins.c hal/components/logic.c hal/components/stream.c
HAL_COMPS += kins sum2 and2 not estop_latch streamer sampler
TESTS += test_hal_core test_hal_cmd test_hal_ini test_hal_graph test_hal_rt test_hal_plugin test_hal_comps
SCRIPT_TESTS += tests/hal/halcmd.sh

# Plugins for test_hal_plugin (never installed): their hal_* symbols come from the test
# program, which exports them (-rdynamic).
HAL_TEST_PLUGINS := $(BUILD)/tests/plugins/hal/demo-plugin.so $(BUILD)/tests/plugins/hal/nosym.so
$(BUILD)/tests/plugins/hal/demo-plugin.so: tests/hal/plugin_demo.c hal/hal.h $(FLAGS_STAMP)
	@mkdir -p $(@D)
	$(call say,SO,$@)
	$(Q)$(CC) $(CPPFLAGS) $(CFLAGS) $(LDFLAGS) -shared $< -o $@
$(BUILD)/tests/plugins/hal/nosym.so: tests/hal/plugin_nosym.c $(FLAGS_STAMP)
	@mkdir -p $(@D)
	$(call say,SO,$@)
	$(Q)$(CC) $(CPPFLAGS) $(CFLAGS) $(LDFLAGS) -shared $< -o $@
$(BUILD)/tests/test_hal_plugin: $(HAL_TEST_PLUGINS)
