#!/usr/bin/env bash
# Runs bench/gui/verify_cost.py in FreeCADCmd with this tree's built workbench (build/workbench)
# (or TOPOPT_WB) installed into a private FreeCAD user home.  bench/gui/run.sh [iterations]
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
home="$(mktemp -d /tmp/topopt-bench-home.XXXXXX)"
trap 'rm -rf "$home"' EXIT
mkdir -p "$home/Mod"
ln -s "${TOPOPT_WB:-$root/build/workbench/TopOpt}" "$home/Mod/TopOpt"
export FREECAD_USER_HOME="$home" OMP_NUM_THREADS=1
export TOPOPT_SHARED_DATA="${TOPOPT_SHARED_DATA:-$root/../shared/data}"
freecadcmd -c "import sys; sys.argv = ['verify_cost', '${1:-0}']; exec(open('$root/bench/gui/verify_cost.py').read())"
