#!/bin/sh
# Installs the Debian packages hexcnc needs, only those that are missing.
# Used by `make deps`; safe to run again.
# libceres-dev: Ceres Solver, the least squares of `hexcnc calibrate fit` (docs/calibration.md).
# linuxcnc-uspace is there for tests only: its `rs274` and the programs and tool tables it
# ships are the reference that hexcnc's G-code and tool-table reading are compared with.
# clang links the libFuzzer target of the interpreter (`make fuzz`; `make test` links it too).
# libcivetweb-dev: the HTTP and WebSocket server of `hexcnc web`, the operator's station.
# mbpoll is there for tests only: a third-party Modbus client for `hexcnc modbus_sim`.
set -eu
PKGS="build-essential pkg-config check libmodbus-dev libeigen3-dev liblcm-dev liblcm-bin \
libinih-dev libglib2.0-dev iproute2 util-linux linuxcnc-uspace mbpoll libceres-dev clang libjansson-dev \
libcivetweb-dev chromium chromium-driver python3-selenium"
missing=""
for p in $PKGS; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
# Node.js and npm build the operator's page (ui/build.sh): Debian's, unless a node and npm
# are already on PATH. chromium, chromium-driver and python3-selenium are for tests only: the
# page is tested in a real browser (tests/e2e/web_station.py).
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
    missing="$missing nodejs npm"
fi
if [ -z "$missing" ]; then
    echo "deps: all packages present"
    exit 0
fi
echo "deps: installing:$missing"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends $missing
