# Shared by fuzz/ci.sh and fuzz/run.sh (sourced, from the repository's top directory).
#
# The fuzz build: the whole project configured with clang++-14 and DRIFTLAB_FUZZ=ON (every library
# instrumented for libFuzzer, AddressSanitizer and UndefinedBehaviorSanitizer; assertions on, -O1),
# but only the fuzz executables built, in build-fuzz/ (DRIFTLAB_FUZZ_BUILD_DIR).

fuzz_build_dir="${DRIFTLAB_FUZZ_BUILD_DIR:-build-fuzz}"
fuzz_cxx="${DRIFTLAB_FUZZ_CXX:-clang++-14}"

# The target names, from fuzz/CMakeLists.txt (name:Function:library entries).
fuzz_targets() {
  sed -n 's/^ *\([a-z_]*\):Fuzz[A-Za-z]*:.*/\1/p' fuzz/CMakeLists.txt
}

# True when clang++-14 can build and link a libFuzzer program (the compiler and its runtime,
# Debian packages clang-14 and libclang-rt-14-dev, are installed).
fuzz_toolchain_available() {
  command -v "$fuzz_cxx" > /dev/null 2>&1 || return 1
  local scratch
  scratch="$(mktemp -d)"
  printf '%s\n' '#include <cstddef>' '#include <cstdint>' \
    'extern "C" int LLVMFuzzerTestOneInput(const uint8_t*, size_t) { return 0; }' \
    > "$scratch/probe.cc"
  local status=0
  "$fuzz_cxx" -fsanitize=fuzzer,address,undefined "$scratch/probe.cc" -o "$scratch/probe" \
    > /dev/null 2>&1 || status=1
  rm -rf "$scratch"
  return "$status"
}

# Configures (once) and builds the fuzz executables.
fuzz_build() {
  local linker=()
  if command -v ld.lld > /dev/null 2>&1; then linker=(-DCMAKE_EXE_LINKER_FLAGS=-fuse-ld=lld); fi
  if [ ! -f "$fuzz_build_dir/CMakeCache.txt" ]; then
    mkdir -p "$fuzz_build_dir"
    cmake -S . -B "$fuzz_build_dir" -G Ninja -DCMAKE_CXX_COMPILER="$fuzz_cxx" \
      -DDRIFTLAB_FUZZ=ON -DDRIFTLAB_BUILD_BENCH=OFF -DDRIFTLAB_PCH=OFF \
      -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -gline-tables-only" \
      "${linker[@]}" > "$fuzz_build_dir/configure.log" 2>&1 ||
      { cat "$fuzz_build_dir/configure.log" >&2; return 1; }
  fi
  cmake --build "$fuzz_build_dir" --target driftlab_fuzzers -j "$(nproc)"
}

# fuzz_run TARGET SECONDS [libFuzzer flags...]: fuzzes TARGET for SECONDS of wall time. New
# inputs go to $fuzz_build_dir/corpus/TARGET (kept between runs); the seeds and the regressions
# of the repository are read as well. A crash, leak, timeout (10 s) or RSS over 2 GB stops the
# run and leaves the input in $fuzz_build_dir/artifacts/TARGET/.
fuzz_run() {
  local target="$1" seconds="$2"
  shift 2
  local work="$fuzz_build_dir/corpus/$target" artifacts="$fuzz_build_dir/artifacts/$target"
  mkdir -p "$work" "$artifacts" "fuzz/regressions/$target"
  "$fuzz_build_dir/fuzz/${target}_fuzzer" -max_total_time="$seconds" -timeout=10 \
    -rss_limit_mb=2048 -max_len=65536 -print_final_stats=1 -artifact_prefix="$artifacts/" "$@" \
    "$work" "fuzz/corpus/$target" "fuzz/regressions/$target"
}
