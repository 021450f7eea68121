#!/usr/bin/env bash
# Runs one Python test module in FreeCAD with the staged workbench installed into a private
# FreeCAD user home (the real one is never touched).
#   run_freecad_test.sh app|gui TEST_FILE STAGED_WORKBENCH_DIR
set -euo pipefail
mode="$1"; test_file="$2"; staged="$3"
here="$(cd "$(dirname "$0")" && pwd)"
home="$(mktemp -d /tmp/topopt-fchome.XXXXXX)"
trap 'rm -rf "$home"' EXIT
mkdir -p "$home/Mod"
ln -s "$staged" "$home/Mod/TopOpt"
export FREECAD_USER_HOME="$home" TOPOPT_TEST_FILE="$test_file" TOPOPT_TEST_HOME="$home"
export TOPOPT_SHARED_DATA="${TOPOPT_SHARED_DATA:-$here/../../../shared/data}"
code="import runpy; runpy.run_path('$here/runner.py', run_name='__main__')"
if [ "$mode" = app ]; then
  exec freecadcmd -c "$code"
else
  # The GUI runs under a virtual X server; the runner exits FreeCAD with the test status.
  # FreeCAD runs a .py given on its command line as a macro once the GUI is up. The Start
  # page uses QtWebEngine, which will not start as root with its sandbox on.
  export QTWEBENGINE_DISABLE_SANDBOX=1 QTWEBENGINE_CHROMIUM_FLAGS="--no-sandbox"
  exec xvfb-run -a -s "-screen 0 1280x1024x24" freecad "$here/runner.py"
fi
