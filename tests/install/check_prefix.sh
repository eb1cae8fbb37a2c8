# Sourced by check_install.sh and check_package.sh: check_prefix PREFIX WORK checks an installed tissue
# as a user of the prefix would use it, with no build tree: a CMake project builds against it
# (find_package(Tissue)), steps and cuts the frog and steps the Tissue FMU (consumer/); tissue-host from
# PREFIX/bin runs a shipped scenario with the shipped FMUs; python3 imports the installed module.
check_prefix() {
  local prefix=$1 work=$2 here
  here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
  echo "== consumer project against $prefix"
  cmake -S "$here/consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release >"$work/consumer.log"
  cmake --build "$work/consumer" -j2 >>"$work/consumer.log" || { cat "$work/consumer.log"; return 1; }
  "$work/consumer/consumer"

  echo "== $prefix/bin/tissue-host run cut_frog_complete.toml --offline"
  "$prefix/bin/tissue-host" run "$prefix/share/tissue/scenarios/cut_frog_complete.toml" --offline \
    --output "$work/session" >"$work/session.log"
  /usr/bin/python3 - "$prefix" "$work/session/summary.json" <<'PY'
import json, os, sys
prefix, summary = os.path.realpath(sys.argv[1]), json.load(open(sys.argv[2]))
for role, path in summary["fmus"].items():
    assert os.path.realpath(path).startswith(prefix + os.sep), f"the {role} FMU came from {path}, not {prefix}"
assert summary["cut_tets"] > 0 and summary["tissue_errors"] == 0, summary
print(f"host: {summary['cut_tets']} tets cut, FMUs from {os.path.dirname(summary['fmus']['tissue'])}")
PY
  # Every file an installed scenario names (its mesh, its render surface) is where it says.
  /usr/bin/python3 - "$prefix/share/tissue/scenarios" <<'PY'
import glob, os, sys, tomllib
named = 0
for scenario in sorted(glob.glob(os.path.join(sys.argv[1], "*.toml"))):
    tissue = tomllib.load(open(scenario, "rb")).get("tissue", {})
    for key in ("mesh", "render_surface"):
        if key in tissue:
            path = os.path.join(os.path.dirname(scenario), tissue[key])
            assert os.path.isfile(path), f"{os.path.basename(scenario)}: {key} {tissue[key]} is not installed"
            named += 1
assert named > 0, "no installed scenario names a file: the check checks nothing"
print(f"scenarios: the {named} files they name are installed")
PY

  echo "== python3 -c 'import tissue' from $prefix"
  PYTHONPATH=$(echo "$prefix"/lib/python3*/dist-packages) /usr/bin/python3 - "$prefix" <<'PY'
import os, sys, tissue
prefix = os.path.realpath(sys.argv[1])
assert os.path.realpath(tissue.__file__).startswith(prefix + os.sep), tissue.__file__
# Installed under /usr or /usr/local, Debian's python3 finds it with no PYTHONPATH.
where = os.path.relpath(os.path.dirname(os.path.realpath(tissue.__file__)), prefix)
for system_prefix in ("/usr", "/usr/local"):
    assert os.path.join(system_prefix, where) in sys.path, f"{system_prefix}/{where} is not on python3's path"
frog = tissue.Tissue()
frog.step()
print(f"python: tissue from {tissue.__file__}, the frog steps")
PY
}
