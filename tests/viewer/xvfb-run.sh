#!/bin/sh
# Runs a test program under a fresh virtual X display (VTK renders through X).
# The server number starts from a per-process value so two tests started in
# the same instant (ctest -j2) do not race for the same display.
exec xvfb-run -a -n $((100 + $$ % 800)) -s "-screen 0 1280x1024x24 -nolisten tcp" "$@"
