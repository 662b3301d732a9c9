#!/usr/bin/env bash
# Regenerates the README's montage (docs/images/montage.png) and its layout
# (montage.json, which the test Compare.TheReadmesMontageShowsTheDefaultTechniquesInTheCurrentLayout
# compares with a default run's, to find the picture stale) from the demo's own run.
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/demo.sh > /dev/null
cp out/montage.png out/montage.json docs/images/
echo "docs/images/montage.png and montage.json from: bash scripts/demo.sh" >&2
