#!/usr/bin/env bash
# graspsim sweep --slurm when squeue fails for a while (the controller restarting): a failed squeue
# must not be taken as the array's end. Stand-ins on PATH, no Slurm: sbatch runs the one array
# task itself and prints a job id; squeue fails (exit 1, Slurm's own message) on its first two
# calls and answers "nothing queued" (exit 0, no output) on the third. The sweep must ask three
# times (ending at the first failure was the defect), then write the run's row: exit 0.
# Usage: test_sweep_squeue_fails.sh GRASPSIM SOURCE_DIR TMP_DIR
set -u
cli=$1 src=$2 tmp=$3/sweep_squeue_fails
source "$src/tests/sweep/sweep_common.sh"
rm -rf "$tmp" && mkdir -p "$tmp/bin" || exit 1

cat >"$tmp/bin/sbatch" <<'SH'
#!/bin/sh
for script; do :; done   # the last argument: the job script
SLURM_ARRAY_TASK_ID=0 sh "$script" >/dev/null 2>&1
echo 42
SH
cat >"$tmp/bin/squeue" <<SH
#!/bin/sh
echo x >>"$tmp/squeue.calls"
[ \$(wc -l <"$tmp/squeue.calls") -ge 3 ] && exit 0
echo "slurm_load_jobs error: Unable to contact slurm controller (connect failure)" >&2
exit 1
SH
chmod +x "$tmp/bin/sbatch" "$tmp/bin/squeue"

PATH="$tmp/bin:$PATH" "$cli" sweep "$src/scenarios/two_finger_lift.lua" --grid mu=0.6 --slurm --out "$tmp/out" \
  >"$tmp/sweep.log" 2>&1
rc=$?
calls=$(wc -l <"$tmp/squeue.calls")
[ "$calls" -eq 3 ] || { cat "$tmp/sweep.log"; fail "squeue was asked $calls times, expected 3 (two failures, then empty)"; }
[ $rc -eq 0 ] || { cat "$tmp/sweep.log"; fail "the sweep exited $rc"; }
grep -q "1 pass" "$tmp/sweep.log" || { cat "$tmp/sweep.log"; fail "the run's row is not in the table"; }
echo "ok: two failed squeue calls were retried; the third's empty answer ended the wait (exit 0, 1 pass)"
