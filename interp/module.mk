# interp/: the RS274/NGC interpreter and the canonical command stream.
LIB_SRCS += interp/canon.c
LIB_SRCS += interp/interp.c interp/lexer.c interp/number.c interp/expr.c interp/block.c \
            interp/exec.c interp/arc.c interp/cycles.c interp/offsets.c interp/params.c \
            interp/printer.c interp/named.c interp/predef.c interp/settings.c \
            interp/oword.c interp/oword_fanuc.c interp/spline.c interp/messages.c \
            interp/probe.c interp/probe_model.c
LIB_SRCS += interp/ccomp.c interp/ccomp_arc.c interp/ccomp_queue.c
LIB_SRCS += interp/comp5.c interp/comp5_join.c interp/comp5_gouge.c interp/tooltable.c \
            interp/tooltable_parse.c interp/tooltable_file.c
TESTS += test_comp5 test_comp5_join test_comp5_gouge test_tooltable test_tooltable_file
SCRIPT_TESTS += tests/paper_programs.sh tests/comp5_gouge_cli.sh
TESTS += test_interp test_interp_number test_interp_motion test_interp_setup test_interp_cycles test_interp_named
TESTS += test_interp_params test_interp_ccomp test_interp_probe
BENCHES += bench_interp bench_oword
SCRIPT_TESTS += tests/interp_expected.sh tests/interp_errors.sh tests/linuxcnc_tooltables.sh \
                tests/linuxcnc_corpus.sh
LIB_SRCS += interp/interp_setup.c
LIB_SRCS += interp/rotation.c interp/nurbs.c interp/feed.c interp/sync.c
TESTS += test_interp_spline test_interp_feed test_interp_sync
TESTS += test_interp_rotation
