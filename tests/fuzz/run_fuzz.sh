#!/usr/bin/env bash
# Builds the libFuzzer target fuzz_front_end with clang++ (ASan + UBSan) in its
# own build directory, seeds a corpus from configs/ and tests/lint/, and fuzzes
# for SECONDS (default 60). Exits non-zero when the fuzzer finds a crash.
#   tests/fuzz/run_fuzz.sh [SECONDS]
set -euo pipefail
seconds="${1:-60}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${KAGE_FUZZ_BUILD_DIR:-$root/build-fuzz}"
corpus="$build/corpus"
artifacts="$build/artifacts"

command -v clang++ >/dev/null || { echo "run_fuzz.sh: clang++ is required" >&2; exit 2; }
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DKAGE_BUILD_FUZZERS=ON \
  -DCMAKE_CXX_FLAGS="-fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer" >/dev/null
cmake --build "$build" --target fuzz_front_end -j"${KAGE_FUZZ_JOBS:-2}"
fuzzer="$build/tests/compiler/fuzz_front_end"
[ -x "$fuzzer" ] || { echo "run_fuzz.sh: $fuzzer was not built" >&2; exit 2; }

mkdir -p "$corpus" "$artifacts"
find "$root/configs" "$root/tests/lint" -name '*.yaml' -type f | while read -r f; do
  cp "$f" "$corpus/seed_$(echo "$f" | sha1sum | cut -c1-16).yaml"
done

cd "$build"  # the target reads configs/ and assets/ of the source tree, nothing else
status=0
"$fuzzer" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=4096 -max_len=8192 \
  -artifact_prefix="$artifacts/" -print_final_stats=1 "$corpus" 2> >(tee "$build/fuzz.log" >&2) || status=$?
wait  # for tee
if [ "$status" -ne 0 ]; then
  echo "run_fuzz.sh: the fuzzer found a problem (exit $status); inputs are in $artifacts" >&2
  exit 1
fi
fixpoints=$(sed -n 's/^fuzz_front_end: \([0-9]*\) inputs reached the fixpoint$/\1/p' "$build/fuzz.log" | tail -1)
if [ -z "$fixpoints" ] || [ "$fixpoints" -eq 0 ]; then
  echo "run_fuzz.sh: no input reached the parse -> resolve -> dump fixpoint; the run proved nothing" >&2
  exit 1
fi
echo "run_fuzz.sh: no crash in ${seconds}s; ${fixpoints} inputs reached the fixpoint"
