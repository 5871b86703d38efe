#!/bin/sh
# Runs every test program, then every test script; prints each one's output (Check's summary
# lines among it) and a closing total. Exit status is non-zero if anything failed.
# Usage: run-tests.sh PROG... -- SCRIPT...
passed=0; failed=0; failed_names=""
mode=prog
for t in "$@"; do
    if [ "$t" = "--" ]; then mode=script; continue; fi
    echo "== $(basename "$t")"
    if [ "$mode" = prog ]; then "$t"; else sh "$t"; fi
    if [ $? -eq 0 ]; then passed=$((passed + 1)); else failed=$((failed + 1)); failed_names="$failed_names $(basename "$t")"; fi
done
echo
[ -n "$failed_names" ] && echo "failed test programs:$failed_names"
echo "test programs: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
