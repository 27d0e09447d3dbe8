#!/usr/bin/env bash
# One piglit test program run under `capture`, for scripts/piglit_compare.sh: that script points
# piglit's PIGLIT_BUILD_DIR at a folder whose bin/ holds a link to this file under the name of
# every piglit program, so each process piglit starts runs as
#   capture --output DIR/NAME.PID.vcap -- /usr/lib/.../piglit/bin/NAME ARGS...
# (the layer preloaded and capturing, exactly as a user's `capture` sets it up). The capture is
# deleted once the program has ended; one line per process (name, exit status, bytes of capture)
# goes to DIR/processes.tsv, so the run can show that every test program was captured.
#
# Environment (set by piglit_compare.sh): VIPER_PIGLIT_CAPTURE (the capture launcher),
# VIPER_PIGLIT_REAL_BIN (piglit's own bin/), VIPER_PIGLIT_CAPTURE_DIR (where captures go).
#
# The one translation: `capture` reports a program killed by signal N as exit status 128+N, and
# piglit counts a crash only from a process killed by a signal; so the wrapper ends itself with the
# same signal. Every other exit status (capture's 74 for a capture that failed while the program
# ran included) reaches piglit unchanged.
name=${0##*/}
real="${VIPER_PIGLIT_REAL_BIN:?}/$name"
dir="${VIPER_PIGLIT_CAPTURE_DIR:?}"
vcap="$dir/$name.$$.vcap"
"${VIPER_PIGLIT_CAPTURE:?}" --output "$vcap" -- "$real" "$@"
rc=$?
bytes=$(stat -c %s "$vcap" 2> /dev/null || echo -)
rm -f "$vcap"
printf '%s\t%s\t%s\n' "$name" "$rc" "$bytes" >> "$dir/processes.tsv"
if [ "$rc" -gt 128 ] && [ "$rc" -lt 160 ]; then
  sig=$((rc - 128))
  trap - "$sig" 2> /dev/null
  ulimit -c 0
  kill -"$sig" $$
fi
exit "$rc"
