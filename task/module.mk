# task/: the runner behind `hexcnc run`: INI + HAL files, interpret and plan the whole
# program, run it on the servo thread, watch every period, summarise.
LIB_SRCS += task/runner.c task/runner_exec.c task/runner_settings.c task/runner_stream.c
# The machine session (`hexcnc machine`, docs/api.md).
LIB_SRCS += task/session.c task/session_machine.c task/session_prog.c task/session_status.c \
            task/session_server.c task/session_api.c
TESTS += test_e2e test_run_faults test_run_settings test_run_startup
BENCHES += bench_servo bench_session
SCRIPT_TESTS += tests/bench_servo_runs.sh
SCRIPT_TESTS += tests/e2e/run_cli.sh
SCRIPT_TESTS += tests/e2e/run_large.sh tests/e2e/machine_session.sh tests/e2e/python_client.sh \
                tests/e2e/stream_session.sh tests/e2e/machine_probe.sh tests/e2e/jerk_session.sh \
                tests/e2e/machine_sync.sh
