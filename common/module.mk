# common/: small pieces shared by several folders (libc, and libinih for the INI reader).
LIB_SRCS += common/errbuf.c common/plugin_dirs.c common/inifile.c
LIB_SRCS += common/config_value.c common/config_keys.c common/config_check.c common/config_doc.c
$(BUILD)/common/plugin_dirs.o: CPPFLAGS += -DHEXCNC_PREFIX='"$(PREFIX)"'
TESTS += test_inifile test_config
SCRIPT_TESTS += tests/ini_doc_fresh.sh tests/ini_check_cli.sh tests/sample_configs.sh
# Replacing a file atomically (tool table, parameter file, plots, sampler output).
LIB_SRCS += common/atomicfile.c
TESTS += test_atomicfile

# `make ini-doc`: docs/ini.md from the key table (tests/ini_doc_fresh.sh keeps them equal).
.PHONY: ini-doc
ini-doc: $(HEXCNC)
	$(HEXCNC) ini doc > docs/ini.md
