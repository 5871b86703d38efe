# fuzz/: libFuzzer target for the interpreter. `make fuzz` builds it with clang
# (-fsanitize=fuzzer,address,undefined) and runs it on fuzz/corpus for FUZZ_TIME seconds.
FUZZ_TIME ?= 60
FUZZ_CC   ?= clang
FUZZ_BIN  := $(BUILD)/fuzz/fuzz_interp
FUZZ_FLAGS := -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
              -D_GNU_SOURCE -I.

# The interpreter's sources are taken from LIB_SRCS when the recipe runs (after every
# module.mk has been read).
$(FUZZ_BIN): fuzz/fuzz_interp.c $(wildcard interp/*.c interp/*.h)
	@mkdir -p $(@D) $(BUILD)/fuzz/new
	$(FUZZ_CC) $(FUZZ_FLAGS) fuzz/fuzz_interp.c $(filter interp/%,$(LIB_SRCS)) -lm -o $@

fuzz: $(FUZZ_BIN)
	@mkdir -p $(BUILD)/fuzz/new
	$(FUZZ_BIN) -max_total_time=$(FUZZ_TIME) -max_len=4096 -timeout=10 \
	    -artifact_prefix=$(BUILD)/fuzz/ $(BUILD)/fuzz/new fuzz/corpus
