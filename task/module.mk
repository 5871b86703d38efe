# task/: the runner behind `hexcnc run`: INI + HAL files, interpret and plan the whole
# program, run it on the servo thread, watch every period, summarise.
LIB_SRCS += task/runner.c task/runner_exec.c
TESTS += test_e2e test_run_faults
BENCHES += bench_servo
SCRIPT_TESTS += tests/e2e/run_cli.sh
SCRIPT_TESTS += tests/e2e/run_large.sh
