#!/bin/sh
# Runs one libFuzzer harness for a fixed time from its seed corpus and says what it did.
#   run_fuzzer.sh FUZZER SOURCE_DIR WORK_DIR SECONDS
# FUZZER: the harness binary (its name picks corpus/<name> and <name>.dict in SOURCE_DIR).
# SOURCE_DIR: tests/fuzz of the source tree.
# WORK_DIR/<name>/corpus keeps the inputs it found (kept between runs: a longer run resumes);
# a crashing input is written to WORK_DIR/<name>/ and named in the output, whose last line is
# also left in WORK_DIR/<name>/summary.txt.
# Exit 0: no finding. Otherwise libFuzzer's status (a crash, a sanitizer report, a timeout of one
# input past 10 s, or more than 2 GB of memory).
set -eu
fuzzer=$1 source_dir=$2 work_dir=$3 seconds=$4
name=$(basename "$fuzzer")
seeds="$source_dir/corpus/$name"
# The scenario loader also starts from every library scenario.
more_seeds=""
[ "$name" = fuzz_scenario ] && more_seeds="$source_dir/../../scenarios"
work="$work_dir/$name"
mkdir -p "$work/corpus"
dict=""
[ -f "$source_dir/$name.dict" ] && dict="-dict=$source_dir/$name.dict"
# Reports on stderr (not into files), symbolized; leaks are findings too.
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:symbolize=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$source_dir/../lsan_suppressions.txt:print_suppressions=0"
log="$work/last-run.log"
status=0
# -close_fd_mask=1: the harness's stdout (a scenario's Lua print) is dropped; libFuzzer reports on stderr.
"$fuzzer" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
  -close_fd_mask=1 -artifact_prefix="$work/" $dict "$work/corpus" "$seeds" $more_seeds >"$log" 2>&1 || status=$?
executions=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
corpus=$(ls "$work/corpus" | wc -l)
if [ "$status" -eq 0 ]; then
  summary="$name: ${executions:-?} executions in $seconds s, no finding (corpus: $corpus inputs kept)"
else
  tail -n 80 "$log"
  summary="$name: FINDING after ${executions:-?} executions (exit $status); the input is in $work/ (log: $log)"
fi
echo "$summary" | tee "$work/summary.txt"
exit "$status"
