#!/usr/bin/env bash
# Coverage-guided fuzzing of framewright's readers with AFL++ (cargo-afl, stable Rust).
#
#   fuzz/run.sh                      # every target, 1,000,000 executions each
#   fuzz/run.sh --execs 50000        # every target, that many executions each
#   fuzz/run.sh --seconds 5          # every target, that long each (the CI smoke run)
#   fuzz/run.sh --seconds 60 urdf    # some targets only
#
# Targets run one after another at low priority. Findings land in fuzz/out/<target>/default/
# {crashes,hangs}; the figures of the last run in fuzz/out/summary.md. Exits 1 when any target
# found a crash or a hang, 2 when the tools are missing.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
shared="$root/../shared"

budget=(-E 1000000)
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --execs) budget=(-E "$2"); shift 2 ;;
    --seconds) budget=(-V "$2"); shift 2 ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    -*) echo "unknown option $1 (see --help)" >&2; exit 2 ;;
    *) targets+=("$1"); shift ;;
  esac
done
[ ${#targets[@]} -gt 0 ] || targets=(ifc rules_front rules_run cell_toml urdf)

if ! cargo afl --version >/dev/null 2>&1; then
  echo "cargo-afl is not installed: cargo install cargo-afl && cargo afl config --build" >&2
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

declare -A dict=([ifc]="$here/dict/step.dict" [rules_front]="$here/dict/rules.dict" [rules_run]="$here/dict/rules.dict")

(cd "$here" && CARGO_BUILD_JOBS="${CARGO_BUILD_JOBS:-1}" nice cargo afl build --release --bins)

# No UI (logs instead), no CPU pinning (the cores are shared).
export AFL_NO_UI=1 AFL_NO_AFFINITY=1 AFL_SKIP_CPUFREQ=1
export AFL_I_DONT_CARE_ABOUT_MISSING_CRASHES=1 AFL_SUPPRESS_WARNINGS=1

found=0
# An empty directory as the working directory: inputs that name relative files find nothing.
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
count() { ls "$1" 2>/dev/null | grep -vc README || true; }
for t in "${targets[@]}"; do
  [ -n "$(ls -A "$here/out/seeds/$t" 2>/dev/null)" ] || { echo "no seeds for $t" >&2; exit 2; }
  x=()
  [ -n "${dict[$t]:-}" ] && x=(-x "${dict[$t]}")
  echo "== fuzzing $t (${budget[*]})"
  rm -rf "$here/out/$t"
  (cd "$work" && nice cargo afl fuzz "${budget[@]}" -t 1000 -m 1024 "${x[@]}" \
     -i "$here/out/seeds/$t" -o "$here/out/$t" "$here/target/release/$t" > "$here/out/$t.log" 2>&1) \
     || { echo "afl-fuzz failed for $t, see fuzz/out/$t.log" >&2; tail -20 "$here/out/$t.log" >&2; exit 2; }
  [ "$(count "$here/out/$t/default/crashes")$(count "$here/out/$t/default/hangs")" = "00" ] || found=1
done

# The figures of the latest run of every target (also of earlier invocations).
summary="$here/out/summary.md"
{
  echo "| target | executions | run time (s) | execs/s | edges found / map | corpus | crashes | hangs |"
  echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
  for t in ifc rules_front rules_run cell_toml urdf; do
    stats="$here/out/$t/default/fuzzer_stats"
    [ -f "$stats" ] || continue
    get() { sed -n "s/^$1 *: *//p" "$stats"; }
    echo "| $t | $(get execs_done) | $(get run_time) | $(get execs_per_sec) | $(get edges_found) / $(get total_edges) | $(get corpus_count) | $(count "$here/out/$t/default/crashes") | $(count "$here/out/$t/default/hangs") |"
  done
} > "$summary"
cat "$summary"
if [ "$found" = 1 ]; then
  echo "findings in fuzz/out/<target>/default/{crashes,hangs}: replay one with" \
       "fuzz/target/release/<target> < FILE, then keep it in tests/fuzz_regressions.rs" >&2
  exit 1
fi
