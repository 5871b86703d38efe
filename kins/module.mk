# kins/: kinematics models behind struct kins_ops, linked into the library for tests and
# tools, and built as lib/kins/<name>.so for loading by name ([KINS] KINEMATICS).
KINS_HEXAPOD_SRCS := kins/hexapod.c kins/hexapod_batch.c kins/hexapod_fwd.c kins/hexapod_geom.c \
                     kins/hexapod_workspace.c kins/kins_cfg.c \
                     common/config_value.c
KINS_TRIVIAL_SRCS := kins/trivial.c kins/kins_cfg.c common/config_value.c

LIB_SRCS += kins/kins.c kins/kins_tcp.c kins/kins_cfg.c kins/hexapod.c kins/hexapod_batch.c kins/hexapod_fwd.c kins/hexapod_geom.c \
            kins/hexapod_workspace.c \
            kins/trivial.c
LIB_CXXSRCS += kins/kins_svd.cpp
PLUGINS += $(LIBDIR)/kins/hexapod.so $(LIBDIR)/kins/trivial.so


# Each plugin binds its own symbols first (-Bsymbolic), so a program that also links the
# same model statically never mixes the two copies; --no-undefined keeps the .so complete.
KINS_SO_LDFLAGS := -shared -Wl,-Bsymbolic -Wl,--no-undefined
$(LIBDIR)/kins/hexapod.so: $(KINS_HEXAPOD_SRCS:%.c=$(BUILD)/%.o) $(BUILD)/kins/kins_svd.o
	@mkdir -p $(@D)
	$(call say,SO,$@)
	$(Q)$(CXX) $(LDFLAGS) $(KINS_SO_LDFLAGS) $^ -lm -o $@
$(LIBDIR)/kins/trivial.so: $(KINS_TRIVIAL_SRCS:%.c=$(BUILD)/%.o)
	@mkdir -p $(@D)
	$(call say,SO,$@)
	$(Q)$(CC) $(LDFLAGS) $(KINS_SO_LDFLAGS) $^ -lm -o $@

TESTS += test_kins test_kins_plugin test_kins_shortcuts
BENCHES += bench_kins
SCRIPT_TESTS += tests/e2e/workspace_cli.sh
