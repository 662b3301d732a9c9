#!/usr/bin/env bash
# The layering rules of docs/architecture.md, checked on every quoted #include of lib/,
# apps/ and python/src/ (ctest: layers.includes):
#  1. no file includes another library's private header (lib/<other>/src/...);
#  2. a library includes only the public headers of the libraries it links (the order
#     below, which lib/CMakeLists.txt's links follow);
#  3. within envmis::core, a stage includes only its own or earlier stages' headers
#     (math, image, compensation, sampling, table; the top-level headers are every
#     stage's).
# Prints each breach as "file:line: the include: why" and exits 1 if there is one.
# Usage: bash scripts/check_layers.sh [source root]   (default: this checkout)
set -euo pipefail
root=${1:-$(cd "$(dirname "$0")/.." && pwd)}
cd "$root"

# What each library may include besides itself (transitively, as it links).
declare -A links=(
    [common]="core"
    [core]="common"
    [build]="core common"
    [study]="build core common"
    [io]="core build"
    [pictures]="io build core"
    [report]="study build core"
    [precompute]="io build study core"
)
stages=(math image compensation sampling table)

# Sets owner to the library that owns a public header envmis/<dir>/...: core's stages and top-level
# headers, else the library of that name.
owner_of() {
    local dir=${1#envmis/}
    dir=${dir%%/*}
    case $dir in
        math | image | compensation | sampling | table | *.h) owner=core ;;
        *) [[ -d lib/$dir/include/envmis/$dir ]] && owner=$dir || owner="" ;;
    esac
}

# Sets rank to the stage's place in stages, or -1.
stage_rank() {
    local i
    rank=-1
    for i in "${!stages[@]}"; do
        [[ ${stages[i]} == "$1" ]] && rank=$i && return
    done
    return 0
}

breaches=0
breach() {
    echo "$1: $2" >&2
    breaches=$((breaches + 1))
}

# check FILE LINE INCLUDE LIBRARY(of the file, or "" for apps and python)
check() {
    local file=$1 line=$2 path=$3 lib=$4 where="$1:$2: #include \"$3\""
    local other
    for other in "${libraries[@]}"; do
        [[ $other == "$lib" ]] && continue
        if [[ -f lib/$other/src/$path ]]; then
            breach "$where" "a private header of envmis::$other"
            return
        fi
    done
    [[ $path == envmis/* ]] || return 0
    owner_of "$path"
    [[ -n $owner ]] || return 0
    if [[ -n $lib && $owner != "$lib" && " ${links[$lib]} " != *" $owner "* ]]; then
        breach "$where" "envmis::$lib does not link envmis::$owner"
        return
    fi
    if [[ $lib == core && $owner == core ]]; then
        local from to
        [[ $file =~ ^lib/core/(include/envmis|src)/([^/]+)/ ]] && stage_rank "${BASH_REMATCH[2]}" || rank=-1
        from=$rank
        [[ $path =~ ^envmis/([^/]+)/ ]] && stage_rank "${BASH_REMATCH[1]}" || rank=-1
        to=$rank
        if ((from >= 0 && to > from)); then
            breach "$where" "stage ${stages[from]} includes the later stage ${stages[to]}"
        fi
    fi
}

libraries=()
for dir in lib/*/; do
    dir=${dir%/}
    libraries+=("${dir#lib/}")
done
owner="" rank=-1
include='^[[:space:]]*#[[:space:]]*include[[:space:]]*"([^"]+)"'
while IFS=: read -r file line text; do
    [[ $text =~ $include ]] || continue
    path=${BASH_REMATCH[1]}
    lib=""
    [[ $file =~ ^lib/([^/]+)/ ]] && lib=${BASH_REMATCH[1]}
    check "$file" "$line" "$path" "$lib"
done < <(grep -rnE '^[[:space:]]*#[[:space:]]*include[[:space:]]*"' lib apps python/src \
    --include='*.h' --include='*.cpp' --include='*.cu' || true)

if ((breaches)); then
    echo "check_layers: $breaches include(s) against the layering (docs/architecture.md)" >&2
    exit 1
fi
echo "check_layers: every include follows the layering"
