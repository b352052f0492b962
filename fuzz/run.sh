#!/usr/bin/env bash
# Coverage-guided fuzzing of framewright's readers with libFuzzer (cargo-fuzz).
#
#   fuzz/run.sh                      # every target, 1,000,000 executions each
#   fuzz/run.sh --execs 50000        # every target, that many executions each
#   fuzz/run.sh --seconds 20         # every target, that long each
#   fuzz/run.sh --seconds 60 urdf    # some targets only
#   fuzz/run.sh --timeout 5 ...      # a slow input is one past 5 s (default 1 s)
#
# Targets run one after another at low priority, each from its seeds plus the corpus its
# earlier runs kept (fuzz/out/corpus/<target>/). A finding (panic, abort, an input running
# past 1 s, or past 1 GB) stops that target and lands in fuzz/out/findings/<target>/; the
# figures of the last run of each target in fuzz/out/summary.md. Exits 1 when any target found
# something, 2 when cargo-fuzz is missing, 3 when the build failed.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
shared="$root/../shared"

budget=(-runs=1000000)
timeout=1
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --execs) budget=("-runs=$2"); shift 2 ;;
    --seconds) budget=("-max_total_time=$2"); shift 2 ;;
    --timeout) timeout="$2"; shift 2 ;;
    -h|--help) sed -n '2,14p' "$0"; exit 0 ;;
    -*) echo "unknown option $1 (see --help)" >&2; exit 2 ;;
    *) targets+=("$1"); shift ;;
  esac
done
all=(ifc rules_front rules_run cell_toml urdf)
[ ${#targets[@]} -gt 0 ] || targets=("${all[@]}")

if ! cargo fuzz --version >/dev/null 2>&1; then
  echo "cargo-fuzz is not installed: cargo install cargo-fuzz" >&2
  exit 2
fi

# Seeds: the project's own small fixtures, and the shared IFC test cases when present.
# Each is copied into fuzz/out/seeds/<target>/ at run time, so nothing is duplicated in git.
seed() { # seed TARGET PREFIX_BYTE_OR_EMPTY MAX_BYTES FILE...
  local target="$1" prefix="$2" max="$3"; shift 3
  local dir="$here/out/seeds/$target" f
  mkdir -p "$dir"
  for f in "$@"; do
    [ -f "$f" ] || continue
    [ "$(stat -c %s "$f")" -le "$max" ] || continue
    local name
    name="$(echo "$f" | sed "s|^$root/||; s|^$shared/|shared/|; s|/|_|g")"
    { [ -n "$prefix" ] && printf "$prefix"; cat "$f"; } > "$dir/$name"
  done
}
rm -rf "$here/out/seeds"
shopt -s nullglob globstar
seed ifc "" 65536 "$root"/tests/fixtures/**/*.ifc "$root"/examples/models/*.ifc "$shared"/ifc-testcases/*.ifc
rule_files=("$root"/rules/*.dl "$root"/examples/rules/*.dl "$root"/tests/logic/*.dl "$root"/tests/fixtures/**/*.dl)
seed rules_front "" 16384 "${rule_files[@]}"
seed rules_run "" 16384 "${rule_files[@]}"
# cell_toml: the first byte picks the reader (0 cell, 1 tool, 2 robot metadata).
seed cell_toml '\x00' 16384 "$root"/robots/cells/*.toml "$root"/tests/fixtures/cells/*.toml
seed cell_toml '\x01' 16384 "$root"/robots/tools/*.toml
seed cell_toml '\x02' 16384 "$root"/robots/*.toml
seed urdf "" 65536 "$root"/robots/*.urdf "$root"/tests/fixtures/robots/*.urdf
# Inputs that once crashed a target seed it again.
for t in "${all[@]}"; do
  for f in "$root"/tests/fixtures/fuzz/"$t"/*; do
    [ "${f##*.}" = md ] || cp "$f" "$here/out/seeds/$t/kept-$(basename "$f")"
  done
done

declare -A dict=([ifc]="$here/dict/step.dict" [rules_front]="$here/dict/rules.dict" [rules_run]="$here/dict/rules.dict")

# Release build with debug assertions and overflow checks; no sanitizer (safe Rust), so the
# stable toolchain does.
build=(-s none -O -a --fuzz-dir "$here")
(cd "$here" && CARGO_BUILD_JOBS="${CARGO_BUILD_JOBS:-2}" nice cargo fuzz build "${build[@]}") \
  || { echo "the fuzz build failed" >&2; exit 3; }
bin_dir="$here/target/$(rustc -vV | sed -n 's/^host: //p')/release"

found=0
# An empty directory as the working directory: inputs that name relative files find nothing.
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
for t in "${targets[@]}"; do
  [ -n "$(ls -A "$here/out/seeds/$t" 2>/dev/null)" ] || { echo "no seeds for $t" >&2; exit 2; }
  opts=("-timeout=$timeout" -rss_limit_mb=1024 -max_len=65536 -seed=1 -print_final_stats=1
        "-artifact_prefix=$here/out/findings/$t/" "${budget[@]}")
  [ -n "${dict[$t]:-}" ] && opts+=("-dict=${dict[$t]}")
  mkdir -p "$here/out/corpus/$t" "$here/out/findings/$t"
  echo "== fuzzing $t (${budget[*]})"
  start=$(date +%s)
  status=0
  # The binary built above, run directly: `cargo fuzz run` would rebuild it whenever a source
  # file changed during the run, mid-way through the targets.
  (cd "$work" && nice "$bin_dir/$t" "$here/out/corpus/$t" "$here/out/seeds/$t" \
     "${opts[@]}" > "$here/out/$t.log" 2>&1) || status=$?
  echo "$(( $(date +%s) - start ))" > "$here/out/$t.seconds"
  if [ "$status" != 0 ]; then
    found=1
    echo "$t stopped with a finding (exit $status): fuzz/out/$t.log" >&2
    grep -E "^(==[0-9]+== ERROR|thread '.*' panicked|SUMMARY|artifact_prefix|Test unit written)" \
      "$here/out/$t.log" | head -5 >&2 || true
  fi
done

# The figures of the latest run of every target (also of earlier invocations).
summary="$here/out/summary.md"
{
  echo "| target | executions | run time (s) | execs/s | coverage (edges) | features | corpus | findings |"
  echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
  for t in "${all[@]}"; do
    log="$here/out/$t.log"
    [ -f "$log" ] || continue
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
    # libFuzzer's own figure when it finished its runs; else the wall time of `cargo fuzz run`.
    secs=$(sed -n 's/^Done [0-9]* runs in \([0-9]*\) second.*/\1/p' "$log" | tail -1)
    [ -n "$secs" ] || secs=$(cat "$here/out/$t.seconds")
    last=$(grep -E '^#[0-9]+' "$log" | tail -1)
    cov=$(echo "$last" | sed -n 's/.* cov: \([0-9]*\).*/\1/p')
    ft=$(echo "$last" | sed -n 's/.* ft: \([0-9]*\).*/\1/p')
    corp=$(echo "$last" | sed -n 's/.* corp: \([0-9]*\).*/\1/p')
    findings=$(find "$here/out/findings/$t" -type f 2>/dev/null | wc -l)
    echo "| $t | ${runs:-?} | $secs | $(( ${runs:-0} / (secs > 0 ? secs : 1) )) | ${cov:-?} | ${ft:-?} | ${corp:-?} | $findings |"
  done
} > "$summary"
cat "$summary"
if [ "$found" = 1 ]; then
  echo "findings in fuzz/out/findings/<target>/: replay one with" \
       "fuzz/target/x86_64-unknown-linux-gnu/release/<target> FILE, then keep it in" \
       "tests/fixtures/fuzz/<target>/ (tests/fuzz_regressions.rs replays it)" >&2
  exit 1
fi
