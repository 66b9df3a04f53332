#!/bin/sh
# The layering rule holds by itself: a plugin linking only libs/ and its own folder configures; one whose
# core links another plugin's library is refused at configure time, naming both; so is a library whose
# namespace is not its folder's (orogen_check_lib_namespaces). Usage: layering_test.sh WORKDIR
set -u
here=$(cd "$(dirname "$0")" && pwd)
work=$1
rm -rf "$work" && mkdir -p "$work"
cmake -S "$here/layering" -B "$work/ok" >"$work/ok.log" 2>&1 || { cat "$work/ok.log"; echo "FAIL: the clean tree did not configure"; exit 1; }
if cmake -S "$here/layering" -B "$work/across" -DLINK_ACROSS=ON >"$work/across.log" 2>&1; then
  echo "FAIL: a plugin linking another plugin's core configured"; exit 1
fi
tr -s " \n" "  " <"$work/across.log" | grep -q "fixture_core_a, a library defined in plugins/kind/a" ||
  { cat "$work/across.log"; echo "FAIL: the refusal does not name the library and its folder"; exit 1; }
if cmake -S "$here/layering" -B "$work/misnamed" -DWRONG_NAMESPACE=ON >"$work/misnamed.log" 2>&1; then
  echo "FAIL: a library whose namespace names another folder configured"; exit 1
fi
tr -s " \n" "  " <"$work/misnamed.log" | grep -q "libs/misnamed/include/orogen/misnamed/misnamed.hpp: 'namespace orogen::elsewhere {}': the code of libs/misnamed belongs in namespace orogen::misnamed" ||
  { cat "$work/misnamed.log"; echo "FAIL: the refusal does not name the file, its namespace and the folder's"; exit 1; }
echo "ok: the clean tree configures; the cross-plugin link and the misnamed library's namespace are refused"
