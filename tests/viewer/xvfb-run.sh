#!/usr/bin/env bash
# Runs a command under a fresh virtual X display of its own (VTK and ParaView render through X).
#
# Why not `xvfb-run -a`: it picks a display number by looking for a free lock file and then
# starts the server, so two tests started in the same instant (ctest -j2) can pick the same
# number and the loser's server vanishes under its client ("bad X server connection"). Here
# the server picks the number itself (-displayfd) when it has bound the socket, which is
# atomic, and says so only once it accepts connections.
#
# Usage: xvfb-run.sh COMMAND [ARGS...]   exit status: the command's, or 1 if Xvfb did not start.
set -u
if ! command -v Xvfb >/dev/null; then
    echo "xvfb-run.sh: Xvfb is not installed (Debian: apt-get install xvfb)" >&2
    exit 1
fi
tmp=$(mktemp -d "${TMPDIR:-/tmp}/orogen-xvfb.XXXXXX") || exit 1
xvfb_pid=
cleanup() {
    if [ -n "$xvfb_pid" ]; then
        kill "$xvfb_pid" 2>/dev/null
        wait "$xvfb_pid" 2>/dev/null
    fi
    rm -rf "$tmp"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# Xvfb writes "N\n" to fd 3 once display :N is ready. No TCP, no auth file: only local
# clients of this user reach it, for the life of the command.
Xvfb -displayfd 3 -screen 0 1280x1024x24 -nolisten tcp -noreset \
    3>"$tmp/display" >"$tmp/xvfb.log" 2>&1 &
xvfb_pid=$!
for _ in $(seq 1 600); do  # up to 30 s on a loaded machine
    [ -s "$tmp/display" ] && break  # Xvfb writes "N\n" in one write
    if ! kill -0 "$xvfb_pid" 2>/dev/null; then
        echo "xvfb-run.sh: Xvfb exited before it was ready:" >&2
        cat "$tmp/xvfb.log" >&2
        xvfb_pid=
        exit 1
    fi
    sleep 0.05
done
display=$(head -n1 "$tmp/display")
if [ -z "$display" ]; then
    echo "xvfb-run.sh: Xvfb did not report a display within 30 s:" >&2
    cat "$tmp/xvfb.log" >&2
    exit 1
fi
export DISPLAY=":$display"
unset XAUTHORITY
"$@"
status=$?
exit "$status"
