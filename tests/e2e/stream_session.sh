#!/bin/sh
# stream_session.sh: a long program streamed through `hexcnc machine` (stream_session.py,
# standard library only; Debian's python3). Needs HEXCNC_ROOT and HEXCNC_BIN.
set -u
py=/usr/bin/python3
[ -x "$py" ] || py=python3
exec "$py" "${HEXCNC_ROOT:-.}/tests/e2e/stream_session.py"
