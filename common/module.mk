# common/: small pieces shared by several folders (no dependencies beyond libc).
LIB_SRCS += common/plugin_dirs.c
$(BUILD)/common/plugin_dirs.o: CPPFLAGS += -DHEXCNC_PREFIX='"$(PREFIX)"'
