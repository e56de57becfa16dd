#!/bin/sh
# The glfw_forest headless test: renders 30 frames of the flyover under a virtual
# X server with Mesa's software renderer (llvmpipe), writes the last one, and
# checks that it shows terrain and trees.
#   run_headless.sh XVFB_RUN GLFW_FOREST CHECKER SCREENSHOT.ppm [OPTION...]
# Further options go to glfw_forest (--morph).
# Exit status 77 (ctest: skipped) when xvfb-run is missing or the example finds
# no display or OpenGL context.
xvfb_run="$1" example="$2" checker="$3" shot="$4"
shift 4
if [ -z "$xvfb_run" ] || [ ! -x "$xvfb_run" ]; then
    echo "glfw_forest_headless: xvfb-run not found; skipped"
    exit 77
fi
rm -f "$shot"
LIBGL_ALWAYS_SOFTWARE=1 "$xvfb_run" -a -s '-screen 0 1280x720x24' \
    "$example" --frames 30 --target-ms 300 --screenshot "$shot" "$@"
rc=$?
if [ "$rc" -ne 0 ]; then
    echo "glfw_forest_headless: glfw_forest exited with status $rc"
    exit "$rc"
fi
exec "$checker" "$shot"
