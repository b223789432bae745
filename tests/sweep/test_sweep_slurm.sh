#!/usr/bin/env bash
# graspsim sweep --slurm on a one-node Slurm started here on localhost (slurm_localhost.sh,
# Debian's slurm-wlm and munge, which tools/setup.sh installs): the 3 x 3 x 2 lift sweep as a
# job array gives the table a local sweep gives, wall times aside; --resume submits only a run
# without a row, and with every row there submits nothing; the table stays the same. Skipped
# (exit 77), saying why, only where Slurm cannot start. The daemons are stopped however the
# test ends.
# Usage: test_sweep_slurm.sh GRASPSIM SOURCE_DIR TMP_DIR
set -u
cli=$1 src=$2 tmp=$3/sweep_slurm
source "$src/tests/sweep/sweep_common.sh"
lift=$src/scenarios/two_finger_lift.lua
cluster=$tmp/cluster
"$src/tests/sweep/slurm_localhost.sh" stop "$cluster"   # one a killed test left running, if any
rm -rf "$tmp" && mkdir -p "$tmp" || exit 1

trap '"$src/tests/sweep/slurm_localhost.sh" stop "$cluster"' EXIT
SLURM_CONF=$("$src/tests/sweep/slurm_localhost.sh" start "$cluster" 2>"$tmp/start.log")
rc=$?
if [ $rc -eq 77 ]; then echo "SKIP: $(cat "$tmp/start.log")"; exit 77; fi
[ $rc -eq 0 ] || { cat "$tmp/start.log"; fail "slurm_localhost.sh start exited $rc"; }
export SLURM_CONF
echo "ok: a one-node Slurm on localhost ($SLURM_CONF)"

"$cli" sweep "$lift" "${sweep_grid[@]}" --jobs 2 --out "$tmp/local" >"$tmp/local.log" 2>&1 \
  || { cat "$tmp/local.log"; fail "the local sweep exited $?"; }
"$cli" sweep "$lift" "${sweep_grid[@]}" --slurm --out "$tmp/slurm" >"$tmp/slurm.log" 2>&1 \
  || { cat "$tmp/slurm.log"; tail -n 30 "$cluster"/*.log; fail "the --slurm sweep exited $?"; }
grep -q "submitted 18 runs as Slurm job array" "$tmp/slurm.log" || { cat "$tmp/slurm.log"; fail "no job array was submitted"; }
diff <(table_without_wall "$tmp/local/sweep.csv") <(table_without_wall "$tmp/slurm/sweep.csv") \
  || fail "--slurm and local give different tables"
got=$(status_by_point "$tmp/slurm/sweep.csv" | sort)
[ "$got" = "$sweep_expected" ] || fail "status by (mu, mass):"$'\n'"$got"
echo "ok: the job array's table is the local one (18 rows)"

# Resumable likewise: a run without a row is submitted alone, and the table is the same.
rm "$tmp/slurm/runs/0005.row"
"$cli" sweep "$lift" "${sweep_grid[@]}" --slurm --resume --out "$tmp/slurm" >"$tmp/missing.log" 2>&1 \
  || { cat "$tmp/missing.log"; fail "--slurm --resume with run 5 missing exited $?"; }
grep -q "submitted 1 runs as Slurm job array" "$tmp/missing.log" || { cat "$tmp/missing.log"; fail "--resume did not submit run 5 alone"; }
diff <(table_without_wall "$tmp/local/sweep.csv") <(table_without_wall "$tmp/slurm/sweep.csv") \
  || fail "the resumed --slurm table differs from the local one"
echo "ok: --slurm --resume submits only the run without a row, same table"

cp "$tmp/slurm/sweep.csv" "$tmp/first.csv"
"$cli" sweep "$lift" "${sweep_grid[@]}" --slurm --resume --out "$tmp/slurm" >"$tmp/resume.log" 2>&1 \
  || { cat "$tmp/resume.log"; fail "--slurm --resume exited $?"; }
grep -q "submitted" "$tmp/resume.log" && { cat "$tmp/resume.log"; fail "--resume with every row there submitted a job"; }
cmp -s "$tmp/first.csv" "$tmp/slurm/sweep.csv" || fail "--resume wrote another table"
echo "ok: --slurm --resume with every row there submits nothing, same table"
