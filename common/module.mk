# common/: small pieces shared by several folders (libc, and libinih for the INI reader).
LIB_SRCS += common/errbuf.c common/plugin_dirs.c common/inifile.c
LIB_SRCS += common/config_value.c common/config_keys.c common/config_check.c common/config_doc.c
$(BUILD)/common/plugin_dirs.o: CPPFLAGS += -DHEXCNC_PREFIX='"$(PREFIX)"'
TESTS += test_inifile
