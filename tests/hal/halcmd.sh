#!/bin/sh
# halcmd.sh: `hexcnc halcmd` end to end: a HAL file on the simulated clock against its stored
# output, one command from the command line, and an error's message and exit status.
cd "$HEXCNC_ROOT/tests/hal" || exit 1
fail=0

out=$("$HEXCNC_BIN" halcmd -s --run-ms 5 -f halcmd.hal 2>&1)
if [ "$out" != "$(cat halcmd.expected)" ]; then
    echo "halcmd.hal: output differs from halcmd.expected:"; echo "$out"; fail=1
fi

out=$("$HEXCNC_BIN" halcmd -i graph.ini getp "[KINS]JOINTS" 2>&1); rc=$?
want="getp: no pin or parameter '6'"
if [ "$out" != "$want" ] || [ $rc -ne 1 ]; then
    echo "one command: got '$out' (exit $rc), want '$want' (exit 1)"; fail=1
fi

out=$(printf 'loadrt sum2\nsetp sum2.0.gain0 3\ngetp sum2.0.gain0\n' | "$HEXCNC_BIN" halcmd 2>&1)
if [ "$out" != "3" ]; then
    echo "stdin: got '$out', want '3'"; fail=1
fi

out=$("$HEXCNC_BIN" halcmd -f errors/second_writer.hal 2>&1); rc=$?
want="errors/second_writer.hal:4: net: signal 'total' already has a writer 'sum2.0.out'; 'sum2.1.out' cannot also write it"
if [ "$out" != "$want" ] || [ $rc -ne 1 ]; then
    echo "error: got '$out' (exit $rc)"; fail=1
fi

[ $fail -eq 0 ] && echo "halcmd.sh: 4 checks passed"
exit $fail
