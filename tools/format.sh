#!/usr/bin/env bash
# The C++ sources under .clang-format's rule, formatted (tools/format.sh) or checked
# (tools/format.sh --check: exit 1 naming each file that differs; ctest's Format test and so CI run it).
# FORMATTED lists the folders already under the rule: a folder joins when it is formatted in one commit.
set -euo pipefail
cd "$(dirname "$0")/.."
FORMATTED=(libs viewer python kernel gl tests plugins/analyze plugins/erode plugins/export plugins/generate plugins/import plugins/process plugins/render plugins/tectonics)
tool=${CLANG_FORMAT:-clang-format-14}
command -v "$tool" >/dev/null || { echo "format: $tool is not installed (tools/setup.sh installs it)"; exit 2; }
mapfile -t files < <(git ls-files -- "${FORMATTED[@]/%//*.cpp}" "${FORMATTED[@]/%//*.hpp}" 2>/dev/null ||
                     find "${FORMATTED[@]}" -name '*.cpp' -o -name '*.hpp')
if [[ "${1:-}" == "--check" ]]; then
  bad=0
  for f in "${files[@]}"; do
    if ! "$tool" --dry-run --Werror "$f" >/dev/null 2>&1; then
      echo "format: $f differs from .clang-format (run tools/format.sh, or: $tool -i $f)"
      bad=1
    fi
  done
  [[ $bad == 0 ]] && echo "format: ${#files[@]} files follow .clang-format"
  exit $bad
fi
"$tool" -i "${files[@]}"
echo "format: formatted ${#files[@]} files"
