#!/bin/sh
# machine_probe.sh: G38 probing on `hexcnc machine` through its socket (machine_probe.py,
# standard library only; Debian's python3). Needs HEXCNC_ROOT and HEXCNC_BIN (make test sets
# them).
set -u
py=/usr/bin/python3
[ -x "$py" ] || py=python3
exec "$py" "${HEXCNC_ROOT:-.}/tests/e2e/machine_probe.py"
