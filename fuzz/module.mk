# fuzz/: libFuzzer target for the interpreter. `make fuzz` builds it with clang
# (-fsanitize=fuzzer,address,undefined) and runs it on fuzz/corpus for FUZZ_TIME seconds.
# Every build also links the same target with the project's compiler and a small main()
# (fuzz/fuzz_replay.c) that replays fuzz/corpus, which `make test` runs.
FUZZ_TIME ?= 60
FUZZ_CC   ?= clang
FUZZ_BIN  := $(BUILD)/fuzz/fuzz_interp
FUZZ_REPLAY := $(BUILD)/fuzz/fuzz_replay
FUZZ_FLAGS := -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
              -D_GNU_SOURCE -I.
# The interpreter's sources are compiled with the fuzzer's instrumentation (taken from
# LIB_SRCS when the recipe runs, after every module.mk has been read); whatever else they
# call (error formatting, atomic saves, ...) comes from the project's library, so a new
# dependency of the interpreter can never break this link.
$(FUZZ_BIN): fuzz/fuzz_interp.c $(wildcard interp/*.c interp/*.h) $(LIBHEX)
	@mkdir -p $(@D) $(BUILD)/fuzz/new
	$(call say,FUZZ,$@)
	$(Q)$(FUZZ_CC) $(FUZZ_FLAGS) fuzz/fuzz_interp.c $(filter interp/%,$(LIB_SRCS)) \
	    $(LIBHEX) $(LDLIBS) -o $@

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
# `make test` also links the libFuzzer target itself (clang is installed by `make deps`), so
# the fuzz build cannot break unseen; the sanitizer build (O=build/san) leaves it out.
ifneq ($(SAN),1)
test: $(FUZZ_BIN)
endif
