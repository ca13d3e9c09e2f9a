#!/usr/bin/env bash
# Runs one libFuzzer target for a bounded time on a COPY of its committed corpus (the corpus in
# fuzz/corpus/<target>/ is never modified), as a CTest test (docs/fuzzing.md). Fails if the
# fuzzer finds a crash, a sanitizer error, a timeout or an allocation over the RSS limit; the
# input that did it is kept and printed (hex) so that the CI log holds it.
#   fuzz/run.sh FUZZER_BINARY CORPUS_DIR [SECONDS]
set -uo pipefail
fuzzer=$(realpath -m "$1")
corpus=$(realpath -m "$2")
seconds=${3:-60}
if [[ ! -x "$fuzzer" ]]; then
  echo "fuzz: $fuzzer is not built; scripts/bootstrap.sh builds it (cmake -S fuzz -B build-fuzz with clang-14)" >&2
  exit 1
fi
if [[ ! -d "$corpus" ]]; then
  echo "fuzz: no corpus folder $corpus" >&2
  exit 1
fi
work=$(mktemp -d "${TMPDIR:-/tmp}/rths-fuzz-$(basename "$fuzzer").XXXXXX")
mkdir -p "$work/corpus"
cp -R "$corpus"/. "$work/corpus/"
cd "$work" || exit 1
"$fuzzer" "$work/corpus" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=2048 \
  -artifact_prefix="$work/" -print_final_stats=1 -close_fd_mask=1 2>&1 | tee "$work/fuzz.log" | tail -n 60
rc=${PIPESTATUS[0]}
if [[ $rc -ne 0 ]]; then
  echo "fuzz: $(basename "$fuzzer") FAILED (exit $rc); the work folder is kept: $work" >&2
  for f in "$work"/crash-* "$work"/leak-* "$work"/timeout-* "$work"/oom-*; do
    [[ -f "$f" ]] || continue
    echo "fuzz: reproduce with: $fuzzer $f" >&2
    echo "fuzz: the input, hex:" >&2
    od -A d -t x1 "$f" | head -n 64 >&2
  done
  exit 1
fi
rm -rf "$work"
exit 0
