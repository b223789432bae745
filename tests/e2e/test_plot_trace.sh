#!/bin/sh
# tools/plot_trace.py end to end: it plots real traces (with fingers, without, and two overlaid)
# into non-empty PNG files, and refuses what is not a graspsim trace with exit 2, writing
# nothing. Skipped (exit 77) when python3-h5py or python3-matplotlib is missing.
# Usage: test_plot_trace.sh GRASPSIM_CLI SOURCE_DIR TMP_DIR
set -u
cli=$1 src=$2 tmp=$3/plot_trace
py=/usr/bin/python3
plot="$py $src/tools/plot_trace.py"

if ! [ -x "$py" ] || ! "$py" -c 'import h5py, matplotlib, numpy' 2>/dev/null; then
  echo "SKIP: /usr/bin/python3 with h5py and matplotlib is needed" \
       "(Debian packages python3-h5py, python3-matplotlib)"
  exit 77
fi
rm -rf "$tmp" && mkdir -p "$tmp" || exit 1

fail() { echo "FAIL: $*"; exit 1; }

# Exit 0 and a non-empty PNG (checked by its signature), else fail with the output.
plots() {
  out=$1; shift
  $plot "$@" --out "$out" >"$tmp/log" 2>&1 || { cat "$tmp/log"; fail "plot_trace.py $* exited $?"; }
  [ -s "$out" ] || fail "plot_trace.py $* wrote no image $out"
  [ "$(head -c 8 "$out" | od -An -c | tr -d ' ')" = '211PNG\r\n032\n' ] \
    || fail "$out is not a PNG file"
  echo "ok: plot_trace.py $* -> $(wc -c <"$out") bytes"
}

# Exit 2 with a message on stderr naming the file, and no image written.
refuses() {
  what=$1; shift
  $plot "$@" --out "$tmp/refused.png" >"$tmp/log" 2>&1
  rc=$?
  [ $rc -eq 2 ] || { cat "$tmp/log"; fail "$what: exit $rc, expected 2"; }
  grep -q "$what" "$tmp/log" || { cat "$tmp/log"; fail "the message does not name $what"; }
  [ -e "$tmp/refused.png" ] && fail "$what: an image was written"
  echo "ok: refused with exit 2: $(cat "$tmp/log")"
}

# Short runs keep the test quick; an expectation that fails (exit 1) still leaves the trace.
"$cli" run "$src/scenarios/two_finger_lift.lua" --quiet --duration 2.5 --out "$tmp/lift.h5" \
  >/dev/null 2>&1
[ -s "$tmp/lift.h5" ] || fail "graspsim run two_finger_lift wrote no trace"
"$cli" run "$src/scenarios/two_finger_lift.lua" --quiet --duration 2.5 --set mu=0.4 \
  --out "$tmp/lift_mu04.h5" >/dev/null 2>&1
[ -s "$tmp/lift_mu04.h5" ] || fail "graspsim run two_finger_lift --set mu=0.4 wrote no trace"
"$cli" run "$src/scenarios/cube_settle.lua" --quiet --duration 1 --out "$tmp/settle.h5" \
  >/dev/null 2>&1
[ -s "$tmp/settle.h5" ] || fail "graspsim run cube_settle wrote no trace"

plots "$tmp/lift.png" "$tmp/lift.h5"
plots "$tmp/settle.png" "$tmp/settle.h5"          # no fingers
plots "$tmp/compare.png" "$tmp/lift.h5" --compare "$tmp/lift_mu04.h5" --fingers thumb \
  --objects box --t0 1 --t1 2.5
# Default output: next to the trace, named after it.
$plot "$tmp/lift.h5" >/dev/null 2>&1 && [ -s "$tmp/lift.png" ] || fail "default --out"

echo "not HDF5" >"$tmp/notes.txt"
"$py" -c 'import h5py, sys; h5py.File(sys.argv[1], "w").create_dataset("x", data=[1])' \
  "$tmp/foreign.h5" || fail "cannot write a foreign HDF5 file"
refuses "$tmp/notes.txt" "$tmp/notes.txt"
refuses "$tmp/foreign.h5" "$tmp/foreign.h5"
refuses "$tmp/missing.h5" "$tmp/missing.h5"
refuses "$tmp/foreign.h5" "$tmp/lift.h5" --compare "$tmp/foreign.h5"
refuses "pinky" "$tmp/lift.h5" --fingers pinky
echo "PASS"
