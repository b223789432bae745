#!/usr/bin/env bash
# graspsim sweep, locally: the 3 x 3 x 2 lift sweep (sweep_common.sh says why each point passes
# or fails) with --jobs 2 and --jobs 1 gives the same table, wall times aside, since every run is
# deterministic; the pass/fail table is the friction threshold's; the HDF5 table holds the CSV's
# columns; --resume keeps finished rows and reruns only a missing one; --keep-traces keeps a trace
# per run; a run in error is reported with its message; bad input exits 2 naming the flag and
# leaves an existing sweep as it was.
# Usage: test_sweep_local.sh GRASPSIM SOURCE_DIR TMP_DIR
set -u
cli=$1 src=$2 tmp=$3/sweep_local
source "$src/tests/sweep/sweep_common.sh"
lift=$src/scenarios/two_finger_lift.lua
rm -rf "$tmp" && mkdir -p "$tmp" || exit 1

"$cli" sweep "$lift" "${sweep_grid[@]}" --jobs 2 --out "$tmp/j2" >"$tmp/j2.log" 2>&1 \
  || { cat "$tmp/j2.log"; fail "the --jobs 2 sweep exited $?"; }
"$cli" sweep "$lift" "${sweep_grid[@]}" --jobs 1 --out "$tmp/j1" >"$tmp/j1.log" 2>&1 \
  || { cat "$tmp/j1.log"; fail "the --jobs 1 sweep exited $?"; }
[ "$(wc -l <"$tmp/j2/sweep.csv")" -eq 19 ] || fail "sweep.csv has not a header and 18 rows"
diff <(table_without_wall "$tmp/j1/sweep.csv") <(table_without_wall "$tmp/j2/sweep.csv") \
  || fail "--jobs 1 and --jobs 2 give different tables"
echo "ok: --jobs 1 and --jobs 2: the same 18 rows"
got=$(status_by_point "$tmp/j2/sweep.csv" | sort)
[ "$got" = "$sweep_expected" ] || fail "status by (mu, mass):"$'\n'"$got"$'\n'"expected:"$'\n'"$sweep_expected"
echo "ok: the pass/fail table is the friction threshold's (mu > m g / 8 N)"
[ "$(head -c 8 "$tmp/j2/sweep.png" | od -An -c | tr -d ' ')" = '211PNG\r\n032\n' ] \
  || fail "no PNG plot $tmp/j2/sweep.png"

# The HDF5 table: the CSV's columns and values (status, pass columns, the mu axis as numbers).
/usr/bin/python3 - "$tmp/j2" <<'PY' || fail "sweep.h5 differs from sweep.csv"
import csv, sys, h5py
d = sys.argv[1]
rows = list(csv.DictReader(open(d + "/sweep.csv", newline="")))
t = h5py.File(d + "/sweep.h5")["runs"]
assert list(t.dtype.names) == list(rows[0].keys()), (t.dtype.names, rows[0].keys())
for i, r in enumerate(rows):
    assert t["mu"][i] == float(r["mu"]) and t["seed"][i] == int(r["seed"])
    assert t["status"][i].decode() == r["status"]
    assert t["pass: the box is lifted at least 5 cm"][i] == int(r["pass: the box is lifted at least 5 cm"])
    assert t["measured: the box is lifted at least 5 cm"][i].decode() == r["measured: the box is lifted at least 5 cm"]
PY
echo "ok: sweep.h5 holds the CSV's columns and values"

# Resume: a finished sweep is refused without --resume; with it, a row removed is rerun alone.
"$cli" sweep "$lift" "${sweep_grid[@]}" --out "$tmp/j2" >"$tmp/again.log" 2>&1
[ $? -eq 2 ] && grep -q -- "--resume" "$tmp/again.log" || { cat "$tmp/again.log"; fail "a second sweep into j2 was not refused"; }
rm "$tmp/j2/runs/0007.row"
"$cli" sweep "$lift" "${sweep_grid[@]}" --out "$tmp/j2" --resume >"$tmp/resume.log" 2>&1 \
  || { cat "$tmp/resume.log"; fail "--resume exited $?"; }
grep -q "17 of 18 runs are done already" "$tmp/resume.log" || { cat "$tmp/resume.log"; fail "--resume reran finished runs"; }
diff <(table_without_wall "$tmp/j1/sweep.csv") <(table_without_wall "$tmp/j2/sweep.csv") \
  || fail "the resumed table differs"
echo "ok: --resume reran 1 run of 18, same table"

# --keep-traces: a trace per run, named in the table.
"$cli" sweep "$lift" --grid mu=0.2,1.2 --keep-traces --out "$tmp/traces" >"$tmp/traces.log" 2>&1 \
  || { cat "$tmp/traces.log"; fail "--keep-traces exited $?"; }
grep -q "^1,1.2,pass,0,[^,]*,runs/0001.h5," "$tmp/traces/sweep.csv" && [ -s "$tmp/traces/runs/0001.h5" ] \
  || { cat "$tmp/traces/sweep.csv"; fail "--keep-traces: no trace runs/0001.h5 in the table"; }
echo "ok: --keep-traces"

# A run that ends in an error: its row says so and why, and the sweep exits 1. The finger's
# script of error_midway.lua raises an error at t = 0.5 s, so a 0.2 s run passes, a 1 s run not.
"$cli" sweep "$src/tests/e2e/data/error_midway.lua" --grid duration=0.2,1 --out "$tmp/error" >"$tmp/error.log" 2>&1
rc=$?
[ $rc -eq 1 ] || { cat "$tmp/error.log"; fail "a sweep with a run in error exited $rc, expected 1"; }
grep -q '^0,0.2,pass,0,' "$tmp/error/sweep.csv" &&
  grep -q '^1,1,error,2,[^,]*,the run stopped early: .*the hand slipped off the script' "$tmp/error/sweep.csv" \
  || { cat "$tmp/error/sweep.csv"; fail "the run in error is not reported with its message"; }
echo "ok: a run in error: status error, exit 2, its message; the sweep exits 1"

# Bad input: exit 2, the flag or field named, an existing sweep untouched.
before=$(cd "$tmp/j1" && ls -l --time-style=+%s.%N . runs | md5sum)
refused() {
  local what=$1; shift
  "$cli" sweep "$@" >"$tmp/bad.log" 2>&1
  local rc=$?
  [ $rc -eq 2 ] || { cat "$tmp/bad.log"; fail "$*: exit $rc, expected 2"; }
  grep -q -- "$what" "$tmp/bad.log" || { cat "$tmp/bad.log"; fail "$*: the message does not name $what"; }
  echo "ok: refused: $(head -n1 "$tmp/bad.log")"
}
refused "--grid needs NAME=V1,V2" "$lift" --grid mu --out "$tmp/bad"
refused "an empty value" "$lift" --grid mu=0.2,,0.6 --out "$tmp/bad"
refused "unknown field or param 'friction'" "$lift" --grid friction=0.2,0.6 --out "$tmp/bad"
refused "--grid mu=abc" "$lift" --grid mu=0.2,abc --out "$tmp/bad"
refused "--seeds" "$lift" --seeds 0 --out "$tmp/bad"
refused "--out" "$lift" --grid mu=0.2
touch "$tmp/file"
refused "--out $tmp/file/sweep" "$lift" --grid mu=0.2 --out "$tmp/file/sweep"
refused "holds another sweep" "$lift" --grid mu=0.2 --out "$tmp/j1"
refused "holds this sweep already" "$lift" "${sweep_grid[@]}" --out "$tmp/j1"
# A folder with files and no sweep.plan is not written into (its sweep.csv would be replaced).
mkdir -p "$tmp/theirs" && printf 'their table\n' > "$tmp/theirs/sweep.csv"
refused "--out $tmp/theirs is a folder with files and no sweep.plan" "$lift" --grid mu=0.2 --out "$tmp/theirs"
[ "$(cat "$tmp/theirs/sweep.csv")" = "their table" ] && [ ! -e "$tmp/theirs/runs" ] \
  || fail "a refused sweep changed $tmp/theirs"
# The runs' --summary may not be the scenario (it would be written over).
cp "$lift" "$tmp/lift.lua"
"$cli" run "$tmp/lift.lua" --no-trace --summary "$tmp/lift.lua" >"$tmp/bad.log" 2>&1
[ $? -eq 2 ] && grep -q -- "--summary '$tmp/lift.lua' is the scenario" "$tmp/bad.log" && cmp -s "$lift" "$tmp/lift.lua" \
  || { cat "$tmp/bad.log"; fail "run --summary SCENARIO was not refused, or the scenario changed"; }
echo "ok: refused: $(head -n1 "$tmp/bad.log")"
[ ! -e "$tmp/bad" ] || fail "a refused sweep made $tmp/bad"
[ "$(cd "$tmp/j1" && ls -l --time-style=+%s.%N . runs | md5sum)" = "$before" ] || fail "a refused sweep changed $tmp/j1"
echo "ok: bad input refused with exit 2; nothing made or changed"
