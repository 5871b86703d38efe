# fuzz/: libFuzzer target for the interpreter. `make fuzz` builds it with clang
# (-fsanitize=fuzzer,address,undefined) and runs it on fuzz/corpus for FUZZ_TIME seconds.
# Every build also links the same target with the project's compiler and a small main()
# (fuzz/fuzz_replay.c) that replays fuzz/corpus: `make test` runs it, so the target cannot
# stop linking unseen.
FUZZ_TIME ?= 60
FUZZ_CC   ?= clang
FUZZ_BIN  := $(BUILD)/fuzz/fuzz_interp
FUZZ_REPLAY := $(BUILD)/fuzz/fuzz_replay
FUZZ_FLAGS := -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
              -D_GNU_SOURCE -I.
# What the interpreter links besides its own sources (error formatting).
FUZZ_DEPS := common/errbuf.c

# The interpreter's sources are taken from LIB_SRCS when the recipe runs (after every
# module.mk has been read).
$(FUZZ_BIN): fuzz/fuzz_interp.c $(wildcard interp/*.c interp/*.h) $(FUZZ_DEPS)
	@mkdir -p $(@D) $(BUILD)/fuzz/new
	$(FUZZ_CC) $(FUZZ_FLAGS) fuzz/fuzz_interp.c $(filter interp/%,$(LIB_SRCS)) $(FUZZ_DEPS) \
	    -lm -o $@

fuzz: $(FUZZ_BIN)
	@mkdir -p $(BUILD)/fuzz/new
	$(FUZZ_BIN) -max_total_time=$(FUZZ_TIME) -max_len=4096 -timeout=10 \
	    -artifact_prefix=$(BUILD)/fuzz/ $(BUILD)/fuzz/new fuzz/corpus

$(FUZZ_REPLAY): fuzz/fuzz_interp.c fuzz/fuzz_replay.c $(LIBDIR)/libhexcnc.a
	@mkdir -p $(@D)
	$(call say,FUZZ,$@)
	$(Q)$(CC) $(CPPFLAGS) $(CFLAGS) $(LDFLAGS) fuzz/fuzz_interp.c fuzz/fuzz_replay.c \
	    $(LIBHEX) $(LDLIBS) -o $@
all: $(FUZZ_REPLAY)
SCRIPT_TESTS += tests/fuzz_replay.sh
