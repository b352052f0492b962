#!/usr/bin/env bash
# same_outputs.sh: prove that two framewright binaries write byte-identical outputs.
#
# Usage: bench/same_outputs.sh OLD_BINARY NEW_BINARY [--quick] [--full] [--keep DIR]
#
#   --quick     only the bundled examples (examples/models/tm1.ifc tm2.ifc tm3.ifc)
#   --full      also simulate g_scale_3storey.ifc (about 90 s per cell per binary)
#   --keep DIR  copy both sides' outputs of every differing comparison into DIR
#
# Models: the bundled examples and, when ../shared exists beside the checkout, every
# ../shared/ifc-testcases/*.ifc, the Constructivity wall (IFC4) and the two autotimber files
# of ../shared/ifc-realworld. Models that `plan` rejects (most h_*) are compared on exit
# status, stdout and stderr of `plan` and `simulate` only.
#
# Every command runs once per binary, each time in a fresh empty working directory at the
# same path, with a fresh empty cache folder ($FRAMEWRIGHT_CACHE and $XDG_CACHE_HOME) and
# --no-cache where the command has it, under `timeout` ($SAME_OUTPUTS_TIMEOUT seconds,
# default 1200). Both binaries are copied first (a build replacing them mid-run cannot mix
# builds) and run through the same path, so argv[0] is the same. Compared: exit status,
# stdout, stderr and every file the command wrote (cmp, recursively for folders).
#
# Output: one line per comparison, `same  plan tm3.ifc` or
# `DIFF  simulate tm3.ifc (framing-line): stdout: first difference at byte N, line L`,
# `FAIL  ...` when a command timed out or wrote nothing where output was expected,
# `skip  ...` for what was left out, then the counts. Exit status 0 only when every
# comparison is the same; 1 otherwise; 2 for a usage error.

set -euo pipefail
export LC_ALL=C

usage() {
    sed -n '2,/^$/{s/^# \{0,1\}//;p}' "$0"
}
die() {
    echo "same_outputs.sh: $*" >&2
    exit 2
}

quick=0
full=0
keep=""
args=()
while [ $# -gt 0 ]; do
    case $1 in
        --quick) quick=1 ;;
        --full) full=1 ;;
        --keep)
            [ $# -ge 2 ] || die "--keep needs a directory"
            keep=$2
            shift
            ;;
        -h | --help)
            usage
            exit 0
            ;;
        -*) die "unknown option: $1 (see --help)" ;;
        *) args+=("$1") ;;
    esac
    shift
done
if [ ${#args[@]} -ne 2 ]; then
    usage >&2
    exit 2
fi

check_binary() {
    [ -e "$1" ] || die "binary not found: $1"
    [ -f "$1" ] || die "not a regular file: $1"
    [ -x "$1" ] || die "not executable: $1"
}
check_binary "${args[0]}"
check_binary "${args[1]}"
command -v timeout >/dev/null || die "timeout (coreutils) is needed"
command -v cmp >/dev/null || die "cmp (diffutils) is needed"

limit=${SAME_OUTPUTS_TIMEOUT:-1200}
case $limit in
    '' | *[!0-9]*) die "SAME_OUTPUTS_TIMEOUT must be a number of seconds" ;;
esac

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
checkout=$(cd "$here/.." && pwd)
shared=$(cd "$checkout/.." && pwd)/shared
if [ -n "$keep" ]; then
    mkdir -p "$keep"
    keep=$(cd "$keep" && pwd)
fi

T=$(mktemp -d "${TMPDIR:-/tmp}/same_outputs.XXXXXX")
cleanup() { rm -rf "$T"; }
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

mkdir "$T/bins" "$T/bin"
cp "${args[0]}" "$T/bins/old"
cp "${args[1]}" "$T/bins/new"
chmod +x "$T/bins/old" "$T/bins/new"
FW=$T/bin/framewright # a symlink to the side being run

started=$SECONDS
n_same=0
n_diff=0
n_fail=0
n_skip=0
n_kept=0

# ---------------------------------------------------------------- comparing

# first_diff A B: nothing when the files are equal, else where they first differ.
first_diff() {
    local out n line
    if out=$(cmp -- "$1" "$2" 2>&1); then
        return 0
    fi
    if [[ $out =~ differ:\ (byte|char)\ ([0-9]+),\ line\ ([0-9]+) ]]; then
        echo "first difference at byte ${BASH_REMATCH[2]}, line ${BASH_REMATCH[3]}"
        return 0
    fi
    # one is a prefix of the other (or empty): the difference is at the byte after its end
    local short=old
    [[ $out == *"EOF on $2"* ]] && short=new
    n=$(stat -c %s -- "$1")
    [ "$short" = new ] && n=$(stat -c %s -- "$2")
    line=$(($(head -c "$n" -- "$1" | tr -cd '\n' | wc -c) + 1))
    echo "first difference at byte $((n + 1)), line $line ($short ends there:" \
        "old $(stat -c %s -- "$1") bytes, new $(stat -c %s -- "$2") bytes)"
}

# tree_diff A B: nothing when the two paths (files or folders) hold the same bytes.
tree_diff() {
    local a=$1 b=$2
    if [ ! -e "$a" ] && [ ! -e "$b" ]; then
        return 0
    fi
    [ -e "$a" ] || { echo "only new wrote it"; return 0; }
    [ -e "$b" ] || { echo "only old wrote it"; return 0; }
    if [ -f "$a" ] && [ -f "$b" ]; then
        first_diff "$a" "$b"
        return 0
    fi
    if [ ! -d "$a" ] || [ ! -d "$b" ]; then
        echo "a file on one side, a folder on the other"
        return 0
    fi
    local la lb
    la=$(cd "$a" && find . -mindepth 1 -printf '%y %P\n' | sort)
    lb=$(cd "$b" && find . -mindepth 1 -printf '%y %P\n' | sort)
    local notes=() p d
    if [ "$la" != "$lb" ]; then
        p=$(comm -23 <(echo "$la") <(echo "$lb") | head -n 3 | cut -c3- | paste -sd, -)
        [ -n "$p" ] && notes+=("only in old: $p")
        p=$(comm -13 <(echo "$la") <(echo "$lb") | head -n 3 | cut -c3- | paste -sd, -)
        [ -n "$p" ] && notes+=("only in new: $p")
    fi
    local ndiff=0 firstfile=""
    while IFS= read -r p; do
        [ -n "$p" ] || continue
        d=$(first_diff "$a/$p" "$b/$p")
        if [ -n "$d" ]; then
            ndiff=$((ndiff + 1))
            [ -n "$firstfile" ] || firstfile="$p: $d"
        fi
    done < <(comm -12 <(echo "$la") <(echo "$lb") | sed -n 's/^f //p')
    if [ $ndiff -gt 0 ]; then
        [ $ndiff -gt 1 ] && firstfile="$firstfile (and $((ndiff - 1)) more files differ)"
        notes+=("$firstfile")
    fi
    if [ ${#notes[@]} -gt 0 ]; then
        local IFS=';'
        echo "${notes[*]}" | sed 's/;/; /g'
    fi
}

report() { # KIND TITLE [PROBLEM...]: print one result line and count it
    local kind=$1 line="$1  $2"
    shift 2
    case $kind in
        same) n_same=$((n_same + 1)) ;;
        DIFF) n_diff=$((n_diff + 1)) ;;
        FAIL) n_fail=$((n_fail + 1)) ;;
        skip) n_skip=$((n_skip + 1)) ;;
    esac
    if [ $# -gt 0 ]; then
        line="$line: $1"
        shift
        local p
        for p in "$@"; do
            line="$line; $p"
        done
    fi
    printf '%s\n' "$line"
}

keep_sides() { # TITLE: copy both sides into $keep
    [ -n "$keep" ] || return 0
    n_kept=$((n_kept + 1))
    local dest
    dest=$keep/$(printf '%03d' "$n_kept")-$(echo "$1" | tr -c 'A-Za-z0-9._-' '_' | cut -c1-80)
    rm -rf "$dest"
    mkdir -p "$dest"
    local side
    for side in old new; do
        mkdir "$dest/$side"
        cp "$T/$side.out" "$dest/$side/stdout"
        cp "$T/$side.err" "$dest/$side/stderr"
        cp "$T/$side.rc" "$dest/$side/exit-status"
        cp -r "$T/$side.dir" "$dest/$side/files"
    done
}

# run_side SIDE ARGS...: run one binary in a fresh empty folder $T/run with a fresh cache,
# then move the folder to $T/SIDE.dir; stdout, stderr and exit status go to $T/SIDE.*.
run_side() {
    local side=$1
    shift
    rm -rf "$T/run" "$T/cache" "$T/$side.dir"
    mkdir "$T/run" "$T/cache"
    ln -sfn "$T/bins/$side" "$FW"
    local rc=0
    (
        cd "$T/run"
        FRAMEWRIGHT_CACHE="$T/cache" XDG_CACHE_HOME="$T/cache" \
            exec timeout --foreground -k 30 "$limit" "$FW" "$@"
    ) </dev/null >"$T/$side.out" 2>"$T/$side.err" || rc=$?
    echo "$rc" >"$T/$side.rc"
    mv "$T/run" "$T/$side.dir"
}

# compare TITLE OUTPUTS -- ARGS...: run ARGS with both binaries and report.
# OUTPUTS: space-separated files or folders the command writes (relative to its working
# folder); `name=path` gives the output its own line titled `name MODEL...` (the title with
# its first word replaced), a bare `path` is folded into the command's line.
compare() {
    local title=$1 outputs=$2
    shift 3 # title, outputs, --
    run_side old "$@"
    run_side new "$@"
    local rco rcn
    rco=$(cat "$T/old.rc")
    rcn=$(cat "$T/new.rc")
    local problems=() fails=() d o name path
    [ "$rco" = 124 ] || [ "$rco" = 137 ] && fails+=("old timed out after ${limit} s")
    [ "$rcn" = 124 ] || [ "$rcn" = 137 ] && fails+=("new timed out after ${limit} s")
    [ "$rco" = "$rcn" ] || problems+=("exit status $rco (old) vs $rcn (new)")
    d=$(first_diff "$T/old.out" "$T/new.out")
    [ -z "$d" ] || problems+=("stdout: $d")
    d=$(first_diff "$T/old.err" "$T/new.err")
    [ -z "$d" ] || problems+=("stderr: $d")
    local own=() declared=()
    for o in $outputs; do
        if [[ $o == *=* ]]; then
            own+=("$o")
            path=${o#*=}
        else
            path=$o
            d=$(tree_diff "$T/old.dir/$path" "$T/new.dir/$path")
            [ -z "$d" ] || problems+=("$path: $d")
            if [ ! -e "$T/old.dir/$path" ] && [ ! -e "$T/new.dir/$path" ] && [ "$rco" = 0 ]; then
                fails+=("neither binary wrote $path")
            fi
        fi
        declared+=("$path")
    done
    # anything else a command wrote into its working folder
    local extra_old extra_new
    for o in old new; do
        rm -rf "$T/$o.extra"
        mkdir "$T/$o.extra"
        (cd "$T/$o.dir" && find . -mindepth 1 -maxdepth 1 -printf '%P\n') | sort |
            while IFS= read -r path; do
                for d in "${declared[@]+"${declared[@]}"}"; do
                    [ "$path" = "$d" ] && continue 2
                done
                cp -r "$T/$o.dir/$path" "$T/$o.extra/"
            done
    done
    d=$(tree_diff "$T/old.extra" "$T/new.extra")
    [ -z "$d" ] || problems+=("other files: $d")
    local kind=same
    if [ ${#fails[@]} -gt 0 ]; then
        kind=FAIL
        problems=("${fails[@]}" "${problems[@]+"${problems[@]}"}")
    elif [ ${#problems[@]} -gt 0 ]; then
        kind=DIFF
    fi
    report "$kind" "$title" "${problems[@]+"${problems[@]}"}"
    local any=$kind
    for o in "${own[@]+"${own[@]}"}"; do
        name=${o%%=*}
        path=${o#*=}
        local otitle="$name ${title#* }"
        d=$(tree_diff "$T/old.dir/$path" "$T/new.dir/$path")
        if [ -n "$d" ]; then
            report DIFF "$otitle" "$d"
            any=DIFF
        elif [ ! -e "$T/old.dir/$path" ] && [ "$rco" = 0 ] && [ "$rcn" = 0 ]; then
            report FAIL "$otitle" "neither binary wrote $path"
            any=FAIL
        else
            report same "$otitle"
        fi
    done
    [ "$any" = same ] || keep_sides "$title"
}

# ---------------------------------------------------------------- what to run

cells_named=$(
    "$T/bins/old" simulate --help 2>/dev/null || true
    "$T/bins/new" simulate --help 2>/dev/null || true
)
extra_cells=()
for c in framing-line study-kuka; do
    if grep -q -- "$c" <<<"$cells_named"; then
        extra_cells+=("$c")
    else
        report skip "cell $c" "neither binary names it in simulate --help"
    fi
done

models=()
cell_models=() # also simulated on the extra cells
for m in tm1 tm2 tm3; do
    f=$checkout/examples/models/$m.ifc
    [ -f "$f" ] || die "missing bundled example: $f"
    models+=("$f")
    cell_models+=("$f")
done
if [ $quick = 0 ]; then
    if [ -d "$shared" ]; then
        for f in "$shared"/ifc-testcases/*.ifc; do
            [ -f "$f" ] && models+=("$f")
        done
        f=$shared/ifc-realworld/timber_constructivity_wall-elemented-case_IFC4.ifc
        if [ -f "$f" ]; then
            models+=("$f")
            cell_models+=("$f")
        else
            report skip "$(basename "$f")" "not found"
        fi
        for f in "$shared"/ifc-realworld/timber_autotimber-*.ifc; do
            [ -f "$f" ] && models+=("$f")
        done
    else
        report skip "shared models" "$shared not found"
    fi
fi

is_cell_model() {
    local c
    for c in "${cell_models[@]}"; do
        [ "$c" = "$1" ] && return 0
    done
    return 1
}

# For `why`: the first element simulate --json reports not framed, else not nailed, else
# the first element.
failing_element() {
    command -v python3 >/dev/null || return 0
    python3 - "$1" <<'EOF' 2>/dev/null || true
import json, sys
try:
    els = json.load(open(sys.argv[1])).get("elements", [])
except Exception:
    sys.exit(0)
for test in (lambda e: e["framing"]["status"] != "framed",
             lambda e: e["nailing"]["status"] not in ("nailed", "none"),
             lambda e: True):
    for e in els:
        try:
            if test(e):
                print(e["id"])
                sys.exit(0)
        except (KeyError, TypeError):
            pass
EOF
}

# ---------------------------------------------------------------- the run

compare "version" "" -- --version
compare "help" "" -- --help
subcommands=$("$T/bins/new" --help 2>/dev/null |
    sed -n '/^Commands:/,/^$/s/^  \([a-z][a-z0-9-]*\)  .*/\1/p' | grep -vx help || true)
for s in $subcommands; do
    compare "help $s" "" -- "$s" --help
done

for model in "${models[@]}"; do
    b=$(basename "$model")
    big=0
    [ "$b" = g_scale_3storey.ifc ] && [ $full = 0 ] && big=1

    compare "plan $b" "" -- plan "$model" --json --no-cache
    plan_ok=0
    [ "$(cat "$T/old.rc")" = 0 ] || [ "$(cat "$T/new.rc")" = 0 ] && plan_ok=1
    compare "plan-text $b" "" -- plan "$model" --no-cache

    if [ $plan_ok = 0 ]; then
        # a rejected input: the error (exit status and stderr) must stay the same
        compare "simulate $b" "" -- simulate "$model" --json --no-cache
        continue
    fi

    cells=("")
    if is_cell_model "$model"; then
        cells+=("${extra_cells[@]+"${extra_cells[@]}"}")
    fi

    for cell in "${cells[@]}"; do
        cellarg=()
        note=""
        if [ -n "$cell" ]; then
            cellarg=(--cell "$cell")
            note=" ($cell)"
        fi
        for fmt in json wbt gltf; do
            [ -n "$cell" ] && n2=" ($cell, $fmt)" || n2=" ($fmt)"
            compare "world $b$n2" "world.$fmt" -- world "$model" "${cellarg[@]+"${cellarg[@]}"}" \
                --format "$fmt" -o "world.$fmt"
        done
        if [ $big = 1 ]; then
            report skip "simulate $b$note" "takes about 90 s per cell per binary; --full runs it"
            continue
        fi
        compare "simulate $b$note" "" -- simulate "$model" "${cellarg[@]+"${cellarg[@]}"}" --json --no-cache
        cp "$T/new.out" "$T/sim-new.json"
        compare "simulate-table $b$note" "simulate-report=report simulate-bcf=topics.bcfzip" -- \
            simulate "$model" "${cellarg[@]+"${cellarg[@]}"}" --no-cache --report report --bcf topics.bcfzip
        if [ -z "$cell" ]; then
            if is_cell_model "$model"; then
                compare "simulate-bcf $b (BCF 2.1)" "topics.bcfzip" -- \
                    simulate "$model" --no-cache --bcf topics.bcfzip --bcf-version 2.1
            fi
            el=$(failing_element "$T/sim-new.json")
            if [ -n "$el" ]; then
                compare "why $b ($el)" "" -- why "$model" "$el" --no-cache
            else
                report skip "why $b" "simulate --json lists no element"
            fi
        fi
    done

    compare "annotate $b (plan only)" "out.ifc" -- annotate "$model" -o out.ifc
    if [ $big = 1 ]; then
        report skip "annotate $b (--simulate)" "simulates; --full runs it"
    else
        compare "annotate $b (--simulate)" "out.ifc" -- annotate "$model" --simulate -o out.ifc
    fi

    if [ "$model" = "$checkout/examples/models/tm3.ifc" ]; then
        compare "compare $b (study-abb, framing-line)" "" -- \
            compare "$model" --cell study-abb --cell framing-line --json --no-cache
        compare "compare-table $b (study-abb, framing-line)" "compare-report=report" -- \
            compare "$model" --cell study-abb --cell framing-line --no-cache --report report
    fi
done

total=$((n_same + n_diff + n_fail))
echo "$total comparisons: $n_same same, $n_diff differ, $n_fail failed ($n_skip skipped)"
echo "same_outputs.sh: took $((SECONDS - started)) s" >&2
[ -n "$keep" ] && [ $n_kept -gt 0 ] && echo "same_outputs.sh: differing outputs kept in $keep" >&2
[ $((n_diff + n_fail)) = 0 ]
