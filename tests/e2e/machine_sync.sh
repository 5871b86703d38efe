#!/bin/sh
# machine_sync.sh: G33.1 rigid tapping on `hexcnc machine` through its socket (machine_sync.py,
# standard library only; Debian's python3). Needs HEXCNC_ROOT and HEXCNC_BIN (make test sets
# them).
set -u
py=/usr/bin/python3
[ -x "$py" ] || py=python3
exec "$py" "${HEXCNC_ROOT:-.}/tests/e2e/machine_sync.py"
