#!/bin/sh
# The headless test of a GLFW example: renders its frames under a virtual X
# server with Mesa's software renderer (llvmpipe), writes the last one, and has
# the checker look at it.
#   run_headless.sh XVFB_RUN PROGRAM CHECKER SCREENSHOT.ppm [OPTION...]
# The options go to the program (--frames N and its own), followed by
# --screenshot SCREENSHOT.ppm; the checker gets SCREENSHOT.ppm.
# Exit status 77 (ctest: skipped) when xvfb-run is missing or the example finds
# no display or OpenGL context.
xvfb_run="$1" example="$2" checker="$3" shot="$4"
shift 4
name="$(basename "$example")"
if [ -z "$xvfb_run" ] || [ ! -x "$xvfb_run" ]; then
    echo "${name}_headless: xvfb-run not found; skipped"
    exit 77
fi
rm -f "$shot"
LIBGL_ALWAYS_SOFTWARE=1 "$xvfb_run" -a -s '-screen 0 1280x720x24' \
    "$example" "$@" --screenshot "$shot"
rc=$?
if [ "$rc" -ne 0 ]; then
    echo "${name}_headless: $name exited with status $rc"
    exit "$rc"
fi
exec "$checker" "$shot"
