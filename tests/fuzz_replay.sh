#!/bin/sh
# fuzz_replay.sh: the fuzz target, linked without libFuzzer, replays fuzz/corpus (every
# input must give commands or a clean error; under `make sanitize` with ASan and UBSan).
set -u
root=${HEXCNC_ROOT:-.}
replay=${HEXCNC_BUILD:-$root/build}/fuzz/fuzz_replay
if [ ! -x "$replay" ]; then
    echo "FAIL $replay was not built (the fuzz target does not link)"
    exit 1
fi
"$replay" "$root"/fuzz/corpus/* || { echo "FAIL fuzz corpus replay"; exit 1; }
echo "ok   fuzz corpus replayed"
