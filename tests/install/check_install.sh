#!/usr/bin/env bash
# cmake --install BUILD --prefix <temporary>, then the prefix checked as a user would use it
# (check_prefix.sh). A ctest (Install.PrefixWorksWithoutTheBuildTree).
set -euo pipefail
build=$(cd "$1" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
source "$(dirname "$0")/check_prefix.sh"
cmake --install "$build" --prefix "$work/prefix" >"$work/install.log"
check_prefix "$work/prefix" "$work"
echo "install: OK"
