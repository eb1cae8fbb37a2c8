#!/usr/bin/env bash
# The Debian packages: cpack -G DEB in BUILD, their names, file lists and Depends checked, then both
# unpacked into a temporary root and checked as an installed prefix (check_prefix.sh). A ctest
# (Install.DebianPackages); `apt install ./tissue_<version>_amd64.deb` is the same files under /usr.
set -euo pipefail
build=$(cd "$1" && pwd)
version=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
source "$(dirname "$0")/check_prefix.sh"
cpack --config "$build/CPackConfig.cmake" -G DEB -B "$work/packages" >"$work/cpack.log" 2>&1 || { cat "$work/cpack.log"; exit 1; }
runtime=$work/packages/tissue_${version}_amd64.deb
dev=$work/packages/tissue-dev_${version}_amd64.deb
ls "$runtime" "$dev" >/dev/null

fail() { echo "check_package: $*" >&2; exit 1; }
contents() { dpkg-deb -c "$1" | awk '{print $NF}' | sed 's|^\./|/|'; }
expect_files() {  # expect_files DEB PATH_REGEX...
  local deb=$1 list; shift
  list=$(contents "$deb")
  for pattern in "$@"; do grep -qxE "$pattern" <<<"$list" || fail "$(basename "$deb") lacks $pattern"; done
  grep -vqE '^/usr(/|$)|^/$' <<<"$list" && fail "$(basename "$deb") installs outside /usr: $(grep -vE '^/usr(/|$)|^/$' <<<"$list" | head -3)"
  grep -q "$build" <<<"$list" && fail "$(basename "$deb") names the build tree"
  true
}
expect_files "$runtime" /usr/bin/tissue-host /usr/bin/tissue-bench /usr/share/tissue/fmus/Tissue.fmu \
  /usr/share/tissue/fmus/HapticLoop.fmu /usr/share/tissue/fmus/fmi2/Tissue.fmu /usr/share/tissue/ssp/TissueHaptic.ssp \
  /usr/share/tissue/scenarios/cut_frog_complete.toml /usr/share/tissue/meshes/frog.veg /usr/share/tissue/view/index.html \
  '/usr/lib/python3\.[0-9]+/dist-packages/tissue\.cpython-3[0-9]+-x86_64-linux-gnu\.so'
expect_files "$dev" /usr/include/tissue/core/tissue.hpp /usr/include/tissue/importer/fmu3.hpp \
  /usr/include/tissue/haptic/haptic_renderer.hpp /usr/lib/libtissue_core.a /usr/lib/cmake/Tissue/TissueConfig.cmake \
  /usr/lib/cmake/Tissue/TissueTargets.cmake
contents "$runtime" | grep -q '^/usr/include' && fail "the runtime package carries headers"

depends=$(dpkg-deb -f "$runtime" Depends)
for package in python3 python3-numpy libcholmod3 libsundials-ida6 "libbullet3[.0-9]*" libzip4 libstdc\\+\\+6; do
  grep -qE "(^|, )$package( |,|$)" <<<"$depends" || fail "tissue does not depend on $package: $depends"
done
grep -qE "^tissue \(= $version\)" <<<"$(dpkg-deb -f "$dev" Depends)" || fail "tissue-dev does not depend on tissue (= $version)"
echo "packages: $(basename "$runtime") ($(contents "$runtime" | wc -l) entries), $(basename "$dev"); Depends: $depends"

dpkg-deb -x "$runtime" "$work/root"
dpkg-deb -x "$dev" "$work/root"
check_prefix "$work/root/usr" "$work"
echo "package: OK"
