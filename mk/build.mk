# hexcnc: the real build. Invoked by the top-level Makefile after mk/deps.sh.
#
# Each folder adds itself through a module.mk that appends to these lists:
#   LIB_SRCS    C sources compiled into lib/libhexcnc.a (everything the binaries link)
#   LIB_CXXSRCS C++ sources for the same library (Eigen lives here only)
#   CMD_SRCS    tools/cmd_NAME.c, each defining `int cmd_NAME(int argc, char **argv)` and
#               `const char cmd_NAME_usage[]`: the subcommands of bin/hexcnc
#   TESTS       test programs: tests/NAME.c -> $(BUILD)/tests/NAME, run by `make test`
#   SCRIPT_TESTS shell test scripts run by `make test` after the programs
#   BENCHES     bench/NAME.c -> $(BUILD)/bench/NAME, run by `make bench`
#   PLUGINS     shared objects under $(LIBDIR)/ (rules in the module.mk that adds them)
#   EXTRA_BINS  further programs under $(BINDIR)/ (rules in the module.mk that adds them)
#   UI_FILES    built files of the operator's page (web/module.mk), under $(O)/share/hexcnc/ui
#   GEN_HDRS    generated headers that sources may include (built before any object)
#   HAL_COMPS   built-in HAL component types: NAME means the library defines
#               `const struct hal_comp_type hal_comp_NAME`; hal_create() registers them all

# O=DIR puts everything (objects, bin/, lib/) under DIR: `make O=build/san` for the sanitizer
# build, or a private tree per developer working in parallel.
O       ?= .
ifeq ($(O),.)
BUILD   := build
else
BUILD   := $(O)
endif
BINDIR  := $(O)/bin
LIBDIR  := $(O)/lib
GENDIR  := $(BUILD)/gen
PREFIX  ?= /usr/local

CC      ?= cc
CXX     ?= c++
PKGS    := libmodbus lcm inih jansson
WARN    := -Wall -Wextra -Wshadow -Wstrict-prototypes -Wmissing-prototypes -Wpointer-arith \
           -Wcast-align -Wwrite-strings -Wundef -Wformat=2 -Wvla -Wnull-dereference \
           -Wdouble-promotion -Wold-style-definition -Wno-unused-parameter
ifneq ($(CI),)
WARN    += -Werror
endif
OPT     ?= -O3 -fno-math-errno
SANFLAGS :=
ifeq ($(SAN),1)
SANFLAGS := -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined
OPT     := -O1
# the four-lane functions' baseline build alone (common/simd.h): the ordinary tests run
# their AVX2 clones on a processor that has AVX2, these the code one without it runs
BASELINE := -DHEXCNC_BASELINE
endif
CPPFLAGS := -D_GNU_SOURCE -I. -I$(GENDIR) $(BASELINE) $(shell pkg-config --cflags $(PKGS))
CFLAGS   := -std=c11 $(OPT) -g -fPIC $(WARN) $(SANFLAGS)
CXXFLAGS := -std=c++17 $(OPT) -g -fPIC -Wall -Wextra -Wshadow $(if $(CI),-Werror) $(SANFLAGS) \
            $(shell pkg-config --cflags eigen3)
LDFLAGS  := $(SANFLAGS)
# Ceres Solver (calib/) ships no .pc file; its CMake config (CeresTargets.cmake) links the
# shared libceres with glog, gflags and threads.
CERES_LIBS := -lceres -lglog -lgflags
LDLIBS   := $(shell pkg-config --libs $(PKGS)) $(CERES_LIBS) -lcivetweb -ldl -lpthread -lm -lstdc++
CHECK_LIBS := $(shell pkg-config --libs check)

# Quiet build: one short line per step; `make V=1` prints the full commands.
ifeq ($(V),1)
Q :=
say = @true
else
Q := @
say = @printf '  %-6s %s\n' $(1) $(2)
endif

LIB_SRCS :=
LIB_CXXSRCS :=
CMD_SRCS :=
TESTS :=
SCRIPT_TESTS :=
BENCHES :=
PLUGINS :=
EXTRA_BINS :=
UI_FILES :=
GEN_HDRS :=
HAL_COMPS :=

# The compiler and its flags, kept in a stamp that changes only when they do: every object
# depends on it, so `make OPT=-O1` (or a new default here) rebuilds what it compiles instead
# of linking objects compiled with different flags.
FLAGS_STAMP := $(BUILD)/flags.stamp
FLAGS_NOW   := $(CC) $(CXX) $(CPPFLAGS) $(CFLAGS) $(CXXFLAGS) $(LDFLAGS)
.PHONY: FORCE
$(FLAGS_STAMP): FORCE
	@mkdir -p $(@D)
	@echo '$(FLAGS_NOW)' | cmp -s - $@ || echo '$(FLAGS_NOW)' > $@

include $(sort $(wildcard */module.mk */*/module.mk))
# The built-in HAL component types, generated from HAL_COMPS.
$(GENDIR)/hal_comps.h: $(wildcard */module.mk */*/module.mk) mk/build.mk
	@mkdir -p $(@D)
	@{ for n in $(sort $(HAL_COMPS)); do echo "HAL_COMP($$n)"; done; } > $@.tmp && mv $@.tmp $@
GEN_HDRS += $(GENDIR)/hal_comps.h


LIB_OBJS := $(LIB_SRCS:%.c=$(BUILD)/%.o) $(LIB_CXXSRCS:%.cpp=$(BUILD)/%.o)
CMD_OBJS := $(CMD_SRCS:%.c=$(BUILD)/%.o) $(BUILD)/tools/hexcnc.o
LIBHEX   := $(LIBDIR)/libhexcnc.a
HEXCNC   := $(BINDIR)/hexcnc
TEST_BINS  := $(TESTS:%=$(BUILD)/tests/%)
BENCH_BINS := $(BENCHES:%=$(BUILD)/bench/%)

.PHONY: all test bench run experiment install fuzz
.DEFAULT_GOAL := all
all: $(HEXCNC) $(PLUGINS) $(EXTRA_BINS) $(UI_FILES)

$(BUILD)/%.o: %.c $(FLAGS_STAMP) | $(GEN_HDRS)
	@mkdir -p $(@D)
	$(call say,CC,$<)
	$(Q)$(CC) $(CPPFLAGS) $(CFLAGS) -MMD -MP -c $< -o $@
$(BUILD)/%.o: %.cpp $(FLAGS_STAMP) | $(GEN_HDRS)
	@mkdir -p $(@D)
	$(call say,CXX,$<)
	$(Q)$(CXX) $(CPPFLAGS) $(CXXFLAGS) -MMD -MP -c $< -o $@

$(LIBHEX): $(LIB_OBJS)
	@mkdir -p $(@D)
	$(call say,AR,$@)
	$(Q)rm -f $@ && ar rcs $@ $^

# The subcommand table of bin/hexcnc, generated from the tools/cmd_*.c files present.
$(GENDIR)/hexcnc_cmds.h: $(CMD_SRCS) mk/build.mk
	@mkdir -p $(@D)
	@{ for f in $(sort $(CMD_SRCS)); do n=$$(basename $$f .c); n=$${n#cmd_}; \
	   echo "HEXCNC_CMD($$n)"; done; } > $@.tmp && mv $@.tmp $@
$(BUILD)/tools/hexcnc.o: $(GENDIR)/hexcnc_cmds.h


$(HEXCNC): $(CMD_OBJS) $(LIBHEX)
	@mkdir -p $(@D)
	$(call say,LINK,$@)
	$(Q)$(CC) $(LDFLAGS) -rdynamic $(CMD_OBJS) $(LIBHEX) $(LDLIBS) -o $@

$(BUILD)/tests/%: tests/%.c $(LIBHEX) | $(GEN_HDRS)
	@mkdir -p $(@D)
	$(call say,TEST,$@)
	$(Q)$(CC) $(CPPFLAGS) $(CFLAGS) $(LDFLAGS) -rdynamic $< $(LIBHEX) $(CHECK_LIBS) $(LDLIBS) -o $@
$(BUILD)/bench/%: bench/%.c $(LIBHEX) | $(GEN_HDRS)
	@mkdir -p $(@D)
	$(call say,BENCH,$@)
	$(Q)$(CC) $(CPPFLAGS) $(CFLAGS) $(LDFLAGS) -rdynamic $< $(LIBHEX) $(LDLIBS) -o $@

# Tests and benches find the tree through these variables, whatever O is.
RUN_ENV := HEXCNC_ROOT=$(CURDIR) HEXCNC_BIN=$(abspath $(HEXCNC)) \
           HEXCNC_PLUGIN_DIR=$(abspath $(LIBDIR)) HEXCNC_BUILD=$(abspath $(BUILD)) \
           CK_DEFAULT_TIMEOUT=120 HEXCNC_SANITIZED=$(if $(SAN),1,0)

# (the benches are built too, so that each still compiles; bench_servo_runs.sh runs one)
test: all $(TEST_BINS) $(BENCH_BINS)
	@$(RUN_ENV) sh mk/run-tests.sh $(TEST_BINS) -- $(SCRIPT_TESTS)

bench: all $(BENCH_BINS)
	@for b in $(BENCH_BINS); do echo "== $$(basename $$b)"; $(RUN_ENV) $$b || exit 1; done

install: all
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(PREFIX)/lib/hexcnc $(DESTDIR)$(PREFIX)/share/hexcnc
	install -m 755 $(HEXCNC) $(EXTRA_BINS) $(DESTDIR)$(PREFIX)/bin/
	[ ! -x scripts/hexcnc-start ] || install -m 755 scripts/hexcnc-start $(DESTDIR)$(PREFIX)/bin/
	[ -z "$(PLUGINS)" ] || cp -r $(LIBDIR)/kins $(DESTDIR)$(PREFIX)/lib/hexcnc/
	cp -r configs examples $(DESTDIR)$(PREFIX)/share/hexcnc/
	[ -z "$(UI_FILES)" ] || cp -r $(O)/share/hexcnc/ui $(DESTDIR)$(PREFIX)/share/hexcnc/

-include $(wildcard $(LIB_OBJS:.o=.d) $(CMD_OBJS:.o=.d))
