# lcmtypes/: LCM message definitions. lcm-gen writes their C code into $(GENDIR)/lcmtypes/ at
# build time (nothing generated is committed); the C files go into the library, and the
# headers into GEN_HDRS, so every object waits for them.
LCM_DEFS := $(sort $(wildcard lcmtypes/*.lcm))
LCM_GEN_C := $(LCM_DEFS:lcmtypes/%.lcm=$(GENDIR)/lcmtypes/%.c)
LCM_GEN_H := $(LCM_DEFS:lcmtypes/%.lcm=$(GENDIR)/lcmtypes/%.h)
GEN_HDRS += $(LCM_GEN_H)
LCM_GEN_OBJS := $(LCM_DEFS:lcmtypes/%.lcm=$(BUILD)/lcmtypes/%.o)

# One lcm-gen run per message: its .c and .h (which includes "lcmtypes/NAME.h").
$(GENDIR)/lcmtypes/%.c $(GENDIR)/lcmtypes/%.h: lcmtypes/%.lcm
	@mkdir -p $(@D)
	$(call say,LCMGEN,$<)
	$(Q)lcm-gen -c --c-cpath $(@D) --c-hpath $(@D) --cinclude lcmtypes $<

# The generated C, compiled like the rest and archived into the library ($^ of its rule).
$(BUILD)/lcmtypes/%.o: $(GENDIR)/lcmtypes/%.c $(GENDIR)/lcmtypes/%.h $(FLAGS_STAMP) | $(GEN_HDRS)
	@mkdir -p $(@D)
	$(call say,CC,$<)
	$(Q)$(CC) $(CPPFLAGS) $(CFLAGS) -c $< -o $@
$(LIBDIR)/libhexcnc.a: $(LCM_GEN_OBJS)
# Keep the generated files: make would delete them as intermediates of the objects.
.SECONDARY: $(LCM_GEN_C) $(LCM_GEN_H)

# The status component, its publisher thread and the lock-free rings it uses.
LIB_SRCS += hal/components/lcm_status.c hal/components/lcm_status_pub.c
HAL_COMPS += lcm_status
TESTS += test_lcm_ring test_lcm_status

# UDP multicast in a network namespace: tests/lcm/udpm.sh with its checker program.
SCRIPT_TESTS += tests/lcm/udpm.sh tests/lcm/sim_run.sh
LCM_CHECK := $(BUILD)/tests/lcm/lcm_check
$(LCM_CHECK): tests/lcm/lcm_check.c $(LIBDIR)/libhexcnc.a | $(GEN_HDRS)
	@mkdir -p $(@D)
	$(call say,TEST,$@)
	$(Q)$(CC) $(CPPFLAGS) $(CFLAGS) $(LDFLAGS) $< $(LIBDIR)/libhexcnc.a $(LDLIBS) -o $@
test: $(LCM_CHECK)
BENCHES += bench_lcm
