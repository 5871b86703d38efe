#!/bin/sh
# web_station.sh: the operator's station in a real browser (web_station.py: headless Debian
# chromium driven by Debian's python3-selenium). Needs HEXCNC_ROOT and HEXCNC_BIN.
set -u
py=/usr/bin/python3
[ -x "$py" ] || py=python3
if ! "$py" -c "import selenium" 2>/dev/null || [ ! -x /usr/bin/chromedriver ]; then
    echo "FAIL web_station: chromium, chromium-driver and python3-selenium are needed (make deps)"
    exit 1
fi
exec "$py" -u "${HEXCNC_ROOT:-.}/tests/e2e/web_station.py"
