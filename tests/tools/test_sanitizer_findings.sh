#!/bin/sh
# tools/sanitizer_findings, which tools/check asks whether the sanitizer build found anything:
# report files that hold only the runtime's warnings (a machine without llvm-symbolizer writes
# "WARNING: invalid path to external symbolizer!" from every process) are no finding, exit 0;
# one file with an AddressSanitizer or LeakSanitizer error or an UndefinedBehaviorSanitizer
# runtime error among them is, exit 1, and is shown. The reports below are the runtimes' own
# formats (Clang 14), shortened.
# usage: test_sanitizer_findings.sh SOURCE_DIR TMP
set -u
script="$1/tools/sanitizer_findings"
dir="$2/sanitizer_findings"
failed=0
check() {   # check WHAT EXPECTED_STATUS [TEXT]: runs the script on $dir
  out=$("$script" "$dir" 2>&1)
  status=$?
  if [ "$status" -ne "$2" ]; then
    echo "FAIL: $1: exit $status, expected $2; output:"; echo "$out"; failed=1
  elif [ $# -gt 2 ] && ! printf '%s' "$out" | grep -qF -- "$3"; then
    echo "FAIL: $1: the output does not say '$3':"; echo "$out"; failed=1
  else
    echo "ok: $1"
  fi
}
fresh() { rm -rf "$dir" && mkdir -p "$dir"; }

fresh
check "no report file" 0
for pid in 101 102 103; do
  printf '==%s==WARNING: invalid path to external symbolizer!\n' "$pid" > "$dir/asan.$pid"
done
printf '==104==WARNING: invalid path to external symbolizer!\n' > "$dir/ubsan.104"
check "warning-only reports" 0 "4 sanitizer report file(s) hold warnings only"

cat > "$dir/asan.200" <<'REPORT'
==200==WARNING: invalid path to external symbolizer!
=================================================================
==200==ERROR: AddressSanitizer: heap-buffer-overflow on address 0x602000000018 at pc 0x55d0 bp 0x7ffd sp 0x7ffd
READ of size 4 at 0x602000000018 thread T0
    #0 0x55d0  (/build-sanitize/tools/graspsim+0x4f1234)
SUMMARY: AddressSanitizer: heap-buffer-overflow (/build-sanitize/tools/graspsim+0x4f1234)
REPORT
check "an AddressSanitizer error among warnings" 1 "sanitizer report $dir/asan.200"

fresh
cat > "$dir/asan.300" <<'REPORT'
==300==ERROR: LeakSanitizer: detected memory leaks
Direct leak of 64 byte(s) in 1 object(s) allocated from:
    #0 0x4a1b  (/build-sanitize/tests/e2e/e2e_tests+0x4a1b)
SUMMARY: AddressSanitizer: 64 byte(s) leaked in 1 allocation(s).
REPORT
check "a leak" 1 "found 1 problem(s)"

fresh
printf '/src/engine/src/x.cpp:12:7: runtime error: signed integer overflow: 2147483647 + 1 cannot be represented in type int\n' > "$dir/ubsan.400"
check "an undefined-behaviour runtime error" 1 "runtime error: signed integer overflow"

fresh
out=$("$script" 2>&1); [ $? -eq 2 ] && echo "ok: usage" || { echo "FAIL: usage: $out"; failed=1; }
rm -rf "$dir"
[ "$failed" -eq 0 ] || exit 1
