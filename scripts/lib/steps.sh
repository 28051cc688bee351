# Shared by scripts/install and scripts/demo (sourced): numbered steps, a build with visible
# progress that builds only what is installed, and the install itself.

prizma_step() {  # prizma_step "what happens now"
  printf '\n==> %s\n' "$*" >&2
}

# Reads `cmake --build` output on stdin: on a terminal one line that updates ("[ 42%] Building …"),
# otherwise every progress line as it comes. Everything goes to $1 (the build log) as well.
prizma_progress() {
  local log="$1" line
  : >"$log"
  if [[ -t 2 ]]; then
    local width=$(( $(tput cols 2>/dev/null || echo 80) - 4 ))
    while IFS= read -r line; do
      printf '%s\n' "$line" >>"$log"
      if [[ $line =~ ^\[\ *[0-9]+%\] ]]; then printf '\r\033[K  %.*s' "$width" "$line" >&2; fi
    done
    printf '\r\033[K' >&2
  else
    while IFS= read -r line; do
      printf '%s\n' "$line" >>"$log"
      if [[ $line =~ ^\[\ *[0-9]+%\] ]]; then printf '  %s\n' "$line" >&2; fi
    done
  fi
}

# prizma_setup ROOT: scripts/setup (the missing Debian packages), unless PRIZMA_SKIP_SETUP=1 (the
# packages are known to be there: CI, the docs tests).
prizma_setup() {
  if [[ "${PRIZMA_SKIP_SETUP:-0}" == 1 ]]; then
    echo "  skipped (PRIZMA_SKIP_SETUP=1)" >&2
    return
  fi
  "$1/scripts/setup"
}

# prizma_build_installed ROOT BUILD: configures BUILD (without the test suites when it is new) and
# builds the target prizma-installed (the tools, and what else is installed), showing progress. On
# failure prints the end of the log and exits. PRIZMA_REUSE_BUILD=1 and a configured BUILD: builds
# the target in BUILD as it is configured (no scripts/build, which configures again): an already
# built tree costs seconds.
prizma_build_installed() {
  local root="$1" build="$2"
  local jobs="${PRIZMA_JOBS:-$(nproc)}"
  mkdir -p "$build"
  local cmd=(env PRIZMA_BUILD_DIR="$build" PRIZMA_BUILD_TARGETS=prizma-installed "$root/scripts/build")
  if [[ "${PRIZMA_REUSE_BUILD:-0}" == 1 && -f "$build/CMakeCache.txt" ]]; then
    cmd=(cmake --build "$build" -j "$jobs" --target prizma-installed)
    echo "  reusing the configured build folder $build (PRIZMA_REUSE_BUILD=1; log: $build/build.log)" >&2
  else
    # A new build folder gets no tests (faster); an existing one keeps its settings (scripts/build
    # would otherwise turn -Werror off in a tree scripts/test built with it, and recompile everything).
    if [[ -f "$build/CMakeCache.txt" ]]; then
      grep -q '^PRIZMA_WERROR:BOOL=ON$' "$build/CMakeCache.txt" && export PRIZMA_WERROR=1
    else
      cmd+=(-DPRIZMA_BUILD_TESTS=OFF)
    fi
    echo "  building in $build with $jobs jobs (log: $build/build.log); a first build from nothing takes about 20 minutes on one core" >&2
  fi
  if ! "${cmd[@]}" 2>&1 | prizma_progress "$build/build.log"; then
    echo "prizma: the build failed; the end of $build/build.log:" >&2
    tail -n 40 "$build/build.log" >&2
    exit 1
  fi
  echo "  built: $build/renderer/prizma-render, $build/relight/prizma-relight, $build/metamer/prizma-metamer" >&2
}

# prizma_install BUILD PREFIX: cmake --install, quietly, stripped (the build folder keeps the debug
# information: gdb and perf on build/'s binaries); lists where things went.
prizma_install() {
  local build="$1" prefix="$2"
  if ! cmake --install "$build" --prefix "$prefix" --strip >"$build/install.log" 2>&1; then
    echo "prizma: the install into $prefix failed:" >&2
    tail -n 20 "$build/install.log" >&2
    exit 1
  fi
  echo "  installed into $prefix: bin/prizma-render, bin/prizma-relight, bin/prizma-metamer;" \
       "data in share/prizma (scenes in share/prizma/scenes), docs in share/doc/prizma" >&2
}

# How to run the installed tools and import the Python module: PATH and PYTHONPATH advice when
# PREFIX/bin is not on PATH, or the module's folder is not one /usr/bin/python3 reads.
prizma_path_advice() {
  local prefix="$1"
  case ":$PATH:" in
    *":$prefix/bin:"*) echo "The tools are on your PATH: prizma-render --help, prizma-relight --help, prizma-metamer --help" ;;
    *) echo "Put the tools on your PATH (add the line to ~/.bashrc to keep it):"
       echo "  export PATH=\"$prefix/bin:\$PATH\""
       echo "then: prizma-render --help, prizma-relight --help, prizma-metamer --help" ;;
  esac
  local module pydir
  module=$(find "$prefix/lib" -path '*/prizma/__init__.py' 2>/dev/null | head -n 1)
  [[ -n "$module" ]] || return 0
  pydir=$(dirname "$(dirname "$module")")
  if /usr/bin/python3 -c 'import sys; sys.exit(0 if sys.argv[1] in sys.path else 1)' "$pydir" 2>/dev/null; then
    echo "The Python module: /usr/bin/python3 -c 'import prizma' (from $pydir)"
  else
    echo "For the Python module (docs/python.md), also:"
    echo "  export PYTHONPATH=\"$pydir\${PYTHONPATH:+:\$PYTHONPATH}\""
    echo "then: /usr/bin/python3 -c 'import prizma; print(prizma.version())'"
  fi
}
