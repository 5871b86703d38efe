# common/: small pieces shared by several folders (libc, and libinih for the INI reader).
LIB_SRCS += common/errbuf.c common/plugin_dirs.c common/inifile.c
$(BUILD)/common/plugin_dirs.o: CPPFLAGS += -DHEXCNC_PREFIX='"$(PREFIX)"'
TESTS += test_inifile
# Replacing a file atomically (tool table, parameter file, plots, sampler output).
LIB_SRCS += common/atomicfile.c
TESTS += test_atomicfile
