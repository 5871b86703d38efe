# tools/: bin/hexcnc. Each tools/cmd_NAME.c is one subcommand (see mk/build.mk).
CMD_SRCS += $(wildcard tools/cmd_*.c)
GEN_HDRS += $(GENDIR)/hexcnc_cmds.h
SCRIPT_TESTS += tests/cli_help.sh
