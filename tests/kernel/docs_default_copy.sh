#!/usr/bin/env bash
# docs/landscape.md opens with the default's terrain: its first ```orogen block must be
# pipelines/default.orogen's statements up to the terrain (comments, blank lines and the exports and
# renders aside), parameter for parameter, so that a change to the default cannot leave the page behind.
set -euo pipefail
source=$1
doc=$source/docs/landscape.md
# The statements of a spec: comments and blank lines dropped, and every line from the first export or
# render on (the outputs, which the page leaves out but one).
terrain() { sed -e 's/[[:space:]]*#.*$//' -e '/^[[:space:]]*$/d' | awk '/^[a-z_]* *= *render:|^export:/ { exit } { print }'; }
shown=$(awk '/^```orogen/ { inside = 1; next } inside && /^```/ { exit } inside { print }' "$doc" | terrain)
default=$(terrain <"$source/pipelines/default.orogen")
[ -n "$shown" ] || { echo "FAIL: docs/landscape.md shows no spec block"; exit 1; }
if [ "$shown" != "$default" ]; then
    echo "FAIL: docs/landscape.md's first spec is not pipelines/default.orogen's terrain:"
    diff <(echo "$shown") <(echo "$default") || true
    exit 1
fi
echo "docs/landscape.md shows the default's terrain as pipelines/default.orogen makes it ($(wc -l <<<"$default") lines)"
