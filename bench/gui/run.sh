#!/usr/bin/env bash
# Runs bench/gui/verify_cost.py (or bench/gui/$TOPOPT_BENCH.py) in FreeCADCmd with this tree's built workbench (build/workbench)
# (or TOPOPT_WB) installed into a private FreeCAD user home.  bench/gui/run.sh [iterations]
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
home="$(mktemp -d /tmp/topopt-bench-home.XXXXXX)"
trap 'rm -rf "$home"' EXIT
mkdir -p "$home/Mod"
ln -s "${TOPOPT_WB:-$root/build/workbench/TopOpt}" "$home/Mod/TopOpt"
export FREECAD_USER_HOME="$home" OMP_NUM_THREADS=1
export TOPOPT_SHARED_DATA="${TOPOPT_SHARED_DATA:-$root/../shared/data}"
script="$root/bench/gui/${TOPOPT_BENCH:-verify_cost}.py"
freecadcmd -c "import sys; sys.path.insert(0, '$root/bench/gui'); sys.argv = ['$script', '${1:-0}']; exec(open('$script').read())"
