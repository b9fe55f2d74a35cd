#!/usr/bin/env bash
# Usage: expect_exit.sh CODE cmd [args...]
# Runs the command and passes when it exits with CODE. For edgefem's error
# code 2 it also checks that stderr is exactly one 'edgefem: error: ' line.
set -u
want=$1
shift
err=$(mktemp)
trap 'rm -f "$err"' EXIT
"$@" 2>"$err"
got=$?
cat "$err" >&2
if [ "$got" -ne "$want" ]; then
    echo "expect_exit: '$*' exited with $got, expected $want" >&2
    exit 1
fi
if [ "$want" -eq 2 ]; then
    if [ "$(wc -l <"$err")" -ne 1 ] || ! grep -q '^edgefem: error: ' "$err"; then
        echo "expect_exit: stderr is not one 'edgefem: error: ' line" >&2
        exit 1
    fi
fi
exit 0
