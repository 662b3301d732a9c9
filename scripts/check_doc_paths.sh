#!/usr/bin/env bash
# Every path a document names exists in this checkout (ctest: docs.paths): its markdown
# links (relative to the document, anchors and web addresses aside) and the repository
# paths it quotes in backticks (those starting with a top-level folder: lib/, apps/,
# tests/, scripts/, docs/, cmake/, python/, data/, .ci/). Prints each missing one as
# "document: path" and exits 1 if there is one.
# Usage: bash scripts/check_doc_paths.sh DOCUMENT.md...   (paths relative to this checkout)
set -euo pipefail
cd "$(dirname "$0")/.."
(($#)) || { echo "usage: check_doc_paths.sh DOCUMENT.md..." >&2; exit 2; }

missing=0
for doc in "$@"; do
    [[ -f $doc ]] || { echo "check_doc_paths: $doc: no such document" >&2; exit 2; }
    dir=$(dirname "$doc")
    while read -r target; do
        target=${target%%#*}
        [[ -z $target || $target == *://* || $target == mailto:* ]] && continue
        [[ -e $dir/$target ]] || { echo "$doc: link to $target: no such path" >&2; missing=$((missing + 1)); }
    done < <(grep -oE '\]\([^) ]+\)' "$doc" | sed -E 's/^\]\((.*)\)$/\1/')
    while read -r quoted; do
        # lib/python3.X/...: an install prefix's layout, not this checkout's.
        [[ $quoted == lib/python* || $quoted == *...* || $quoted == *'*'* || $quoted == *'<'* ]] && continue
        [[ -e $quoted ]] || { echo "$doc: \`$quoted\`: no such path" >&2; missing=$((missing + 1)); }
    done < <(grep -oE '`(lib|apps|tests|scripts|docs|cmake|python|data|\.ci)/[^` ]*`' "$doc" | tr -d '`' | sort -u)
done
if ((missing)); then
    echo "check_doc_paths: $missing path(s) named but missing" >&2
    exit 1
fi
echo "check_doc_paths: every path named exists"
