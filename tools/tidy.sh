#!/usr/bin/env bash
# tools/tidy.sh BUILD_DIR — `make tidy`: clang-tidy-14 with the checks of .clang-tidy (a function of at most
# 150 lines and 8 parameters) over every translation unit of kernel/, libs/, plugins/, viewer/ and python/
# in BUILD_DIR's compile_commands.json. Exit 1 with each function named (file:line) when one is over.
# TIDY_FILES=REGEX checks only the files it matches (a quicker look at one's own change).
#
# The build is GCC's: its flags that clang does not know (-flto's partners, -Wno-psabi...) are dropped from
# a copy of the compilation database, so clang-tidy parses each file as GCC compiles it.
set -euo pipefail
build=${1:?usage: tools/tidy.sh BUILD_DIR}
root=$(cd "$(dirname "$0")/.." && pwd)
db="$build/compile_commands.json"
[[ -f $db ]] || { echo "tidy: $db is missing: configure with cmake first (CMAKE_EXPORT_COMPILE_COMMANDS is on)" >&2; exit 2; }
command -v run-clang-tidy-14 >/dev/null || { echo "tidy: run-clang-tidy-14 not found: apt-get install clang-tidy-14" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
python3 - "$db" "$work/compile_commands.json" "$root" <<'EOF'
import json, re, shlex, sys
src, dst, root = sys.argv[1:4]
drop = re.compile(r'^-(flto.*|fno-fat-lto-objects|fcx-limited-range|Wno-psabi|Wno-restrict|fconcepts-diagnostics-depth=.*|'
                  r'fno-semantic-interposition|fipa-.*|fno-ipa-.*)$')
keep = re.compile(r'^' + re.escape(root) + r'/(kernel|libs|plugins|viewer|python)/')
out = []
for e in json.load(open(src)):
    if not keep.match(e['file']):
        continue
    args = shlex.split(e['command']) if 'command' in e else e['arguments']
    e.pop('command', None)
    e['arguments'] = [a for a in args if not drop.match(a)]
    out.append(e)
json.dump(out, open(dst, 'w'))
print(f'tidy: {len(out)} translation units', file=sys.stderr)
EOF
log="$work/tidy.log"
# clang-tidy finds .clang-tidy at the root above each file. run-clang-tidy prints each file's command and its
# warnings; the verdict is the warnings (WarningsAsErrors makes them errors, so its exit code says the same).
rc=0
run-clang-tidy-14 -p "$work" -j "${JOBS:-2}" -quiet -extra-arg=-Wno-unknown-warning-option \
  "${TIDY_FILES:-$root/(kernel|libs|plugins|viewer|python)/}" >"$log" 2>&1 || rc=$?
sed -i 's/\x1b\[[0-9;]*m//g' "$log"  # no colours in the log
# Each finding with its notes (how many lines or parameters, against which threshold).
awk '/\[readability-function-size/ {print; keep=1; next} /^\// && !/note:/ {keep=0}
     keep && /note: .*threshold/ {print "    " $0}' "$log" |
  sed "s|$root/||g" | awk '!seen[$0]++' >"$work/found"
# tools/tidy-baseline.txt: the functions over the limits when the rule came in ("FILE FUNCTION" a line), each
# to be split; they are reported, not failed. A function not on it fails, and so does a line of it that no
# longer fires (take it off: the list only shrinks).
baseline="$root/tools/tidy-baseline.txt"
if grep -q "clang-diagnostic-error" "$log"; then  # a file clang could not parse: its functions went unchecked
  grep "clang-diagnostic-error" "$log" | sed "s|$root/||g" | sort -u | head -20 >&2
  echo "tidy: clang could not parse the files above, so their functions were not checked" >&2
  exit 1
fi
{ grep "readability-function-size" "$work/found" || true; } | awk '{split($1, a, ":"); print a[1], $4}' |
  tr -d "'" | sort -u >"$work/now"
new_ones=$(comm -23 "$work/now" <(sort -u "$baseline"))
gone=$(comm -13 "$work/now" <(sort -u "$baseline"))
known=$(comm -12 "$work/now" <(sort -u "$baseline") | wc -l)
if [[ -n $new_ones ]]; then
  grep -F -f <(echo "$new_ones" | awk '{print $1}') "$work/found" || true
  echo "tidy: $(echo "$new_ones" | wc -l) function(s) newly over 150 lines or 8 parameters (.clang-tidy): split them" >&2
  echo "$new_ones" | sed 's/^/  /' >&2
  exit 1
fi
if [[ -n $gone && -z ${TIDY_FILES:-} ]]; then  # (a TIDY_FILES run sees only some of them)
  echo "tidy: within the limits now, take them off tools/tidy-baseline.txt:" >&2
  echo "$gone" | sed 's/^/  /' >&2
  exit 1
fi
if ((known > 0)); then
  echo "tidy: $known function(s) of tools/tidy-baseline.txt still over the limits (to split); none new"
fi
if ((rc != 0)) && ((known == 0)); then
  grep -E "error|Error" "$log" | sort -u | head -20 >&2
  echo "tidy: clang-tidy failed without a function-size finding (above); see the errors" >&2
  exit 1
fi
((known > 0)) || echo "tidy: every function of kernel, libs, plugins, viewer and python is within 150 lines and 8 parameters"
