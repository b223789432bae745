# Shared set-up for tools/graspsim, tools/check and tools/fuzz: install the Debian packages that
# are missing, configure once, build incrementally. Sourced, not run; idempotent.
# Environment: GRASPSIM_BUILD_DIR (default build), GRASPSIM_BUILD_TYPE (default Release),
# GRASPSIM_SANITIZE_BUILD_DIR (default build-sanitize).

graspsim_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
graspsim_build=${GRASPSIM_BUILD_DIR:-$graspsim_root/build}
graspsim_cmake_env=()    # e.g. CC=clang CXX=clang++, for the first configure only
# Extra -D options, for the first configure only. The main build (GCC) builds no Clang twin of
# graspsim: tools/check compares the sanitizer build's graspsim, a Clang build, with this build's
# instead (README.md, "Which build checks what").
graspsim_cmake_args=(-DGRASPSIM_COMPILER_TWIN=OFF)

# Everything graspsim needs from Debian 12, and nothing else. hdf5-tools gives h5dump and
# h5ls for looking into traces.
graspsim_packages=(
  g++ make cmake pkg-config git
  libeigen3-dev libfcl-dev liblua5.4-dev libhdf5-dev catch2
  hdf5-tools
  python3-h5py python3-matplotlib   # tools/plot_trace.py; h5py also reads crash-cut traces in
                                    # SWMR mode in tests/e2e/test_crash.cpp
  clang libclang-rt-dev             # the Clang twin (tests/golden/test_compiler_twin.cpp), the
                                    # sanitizer build (its runtimes) and libFuzzer (README.md
                                    # "Sanitizers and fuzzing")
  llvm                              # llvm-symbolizer, which the sanitizers' reports need to name
                                    # functions and lines (Debian's clang does not bring it)
  libcpp-httplib-dev                # `graspsim view`'s HTTP server (view/README.md)
  pybind11-dev python3-dev python3-numpy python3-pytest
                                    # the Python module and its tests (python/README.md), for
                                    # Debian's /usr/bin/python3
  chromium                          # the browser test of `graspsim view` (view/test), headless
  slurm-wlm munge                   # `graspsim sweep --slurm`'s test starts a one-node Slurm on
                                    # localhost (tests/sweep/slurm_localhost.sh)
)
# The page's packages come from the npm registry (view/web/package-lock.json): Node and npm,
# from Debian unless the machine already has them (a Node of its own carries its own npm,
# which Debian's npm package would conflict with).
command -v node >/dev/null || graspsim_packages+=(nodejs)
command -v npm >/dev/null || graspsim_packages+=(npm)

graspsim_install_missing() {
  local missing=() p
  for p in "${graspsim_packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' \
      || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "graspsim: installing missing Debian packages: ${missing[*]}" >&2
  local sudo=()
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || {
      echo "graspsim: need root (or sudo) to install: ${missing[*]}" >&2; return 1; }
    sudo=(sudo)
  fi
  # apt's progress goes to a log, shown only when something fails.
  local log
  log=$(mktemp /tmp/graspsim-apt.XXXXXX.log)
  if "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -qq >"$log" 2>&1 &&
     "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
       "${missing[@]}" >>"$log" 2>&1; then
    rm -f "$log"
  else
    cat "$log" >&2
    echo "graspsim: installing ${missing[*]} failed (log: $log)" >&2
    return 1
  fi
}

# graspsim_build [TARGET...]: configure once, then build the targets (default: everything).
graspsim_build() {
  local jobs
  jobs=$(nproc 2>/dev/null || echo 2)
  local log="$graspsim_build/last-build.log"
  mkdir -p "$graspsim_build" && : >"$log"
  if [ ! -f "$graspsim_build/CMakeCache.txt" ]; then
    echo "graspsim: first build, in $graspsim_build (a few minutes; log: $log)" >&2
    env "${graspsim_cmake_env[@]}" cmake -S "$graspsim_root" -B "$graspsim_build" \
      -DCMAKE_BUILD_TYPE="${GRASPSIM_BUILD_TYPE:-Release}" "${graspsim_cmake_args[@]}" >>"$log" 2>&1 \
      || { cat "$log" >&2; echo "graspsim: configuring failed (log: $log)" >&2; return 1; }
  fi
  local targets=()
  [ $# -gt 0 ] && targets=(--target "$@")
  # Build output goes to a log; on failure, show it. A quiet build keeps `graspsim run` readable.
  if ! cmake --build "$graspsim_build" -j "$jobs" "${targets[@]}" >>"$log" 2>&1; then
    cat "$log" >&2
    echo "graspsim: build failed (log: $log)" >&2
    return 1
  fi
}

# graspsim_use_sanitize_build: later graspsim_build calls build the sanitizer build instead, a
# Clang build with AddressSanitizer, UndefinedBehaviorSanitizer and the fuzzers (GRASPSIM_SANITIZE
# in CMakeLists.txt), without the Debug twin the main build tests. Its GCC-vs-Clang test compares
# its graspsim with the main build's (which tools/check builds first), so no Clang twin is built.
graspsim_use_sanitize_build() {
  local main_build=${GRASPSIM_BUILD_DIR:-$graspsim_root/build}
  graspsim_build=${GRASPSIM_SANITIZE_BUILD_DIR:-$graspsim_root/build-sanitize}
  graspsim_cmake_env=(CC=clang CXX=clang++)
  graspsim_cmake_args=(-DGRASPSIM_SANITIZE=ON -DGRASPSIM_TWIN_BUILD=OFF
                       -DGRASPSIM_COMPILER_TWIN_CLI="$main_build/tools/graspsim")
}

# The page's npm packages (three.js, and playwright-core for its test) in view/web/node_modules,
# installed exactly from the lock file when they are missing or older than it.
graspsim_npm_ci() {
  local web="$graspsim_root/view/web" log
  [ -f "$web/node_modules/.package-lock.json" ] &&
    [ ! "$web/package-lock.json" -nt "$web/node_modules/.package-lock.json" ] && return 0
  echo "graspsim: installing the viewer's npm packages in $web (npm ci)" >&2
  log=$(mktemp /tmp/graspsim-npm.XXXXXX.log)
  if (cd "$web" && npm ci --no-audit --no-fund) >"$log" 2>&1; then
    rm -f "$log"
  else
    cat "$log" >&2
    echo "graspsim: npm ci in $web failed (log: $log)" >&2
    return 1
  fi
}

# graspsim_setup [TARGET...]
graspsim_setup() {
  graspsim_install_missing && graspsim_npm_ci && graspsim_build "$@"
}
