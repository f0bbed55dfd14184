#!/usr/bin/env bash
# The viewer's samples per second on a preset, two builds interleaved
# (issue 33's viewer target): each run opens the window at its default
# size, accumulates for about the same wall time, and its closing
# `quality:` line gives the accumulation's samples per second.
#
#   bash bench/viewer_throughput.sh BEFORE_BINARY AFTER_BINARY [PRESET] [ROUNDS] [SECONDS]
#
# Needs a display (DISPLAY, e.g. Xvfb :77 -screen 0 1600x1000x24). Each
# binary runs until it has drawn for about SECONDS (default 30): its frame
# count is found by a first short run, as frames differ in length between
# builds. VIEWER_ARGS (default `--kernel fragment`, auto's pick on
# lavapipe) go to every run: naming the kernel spares each run auto's
# timing of the kernels at start-up, which a user's settings remember.
# Prints one line per run and the ratio of the means.
set -euo pipefail
before=${1:?before binary}
after=${2:?after binary}
preset=${3:-presets/default.ron}
rounds=${4:-3}
seconds=${5:-30}
read -r -a viewer_args <<<"${VIEWER_ARGS:---kernel fragment}"
: "${DISPLAY:?a display is needed (Xvfb)}"
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp/xdg}
mkdir -p -m 0700 "$XDG_RUNTIME_DIR"

quality() { # binary frames -> the quality line
    timeout 900 "$1" --preset "$preset" --exit-after-frames "$2" "${viewer_args[@]}" 2>&1 | grep '^quality:'
}
field() { # line -> "seconds spp_per_second"
    sed -E 's/.*shown; ([0-9.]+) s, ([0-9.]+) spp\/s.*/\1 \2/' <<<"$1"
}
frames_for() { # binary -> frames that take about $seconds
    local line s
    line=$(quality "$1" 300)
    s=$(field "$line" | cut -d' ' -f1)
    python3 -c "print(max(50, round(300 * $seconds / max($s, 0.1))))"
}

declare -A frames rates
for b in before after; do
    bin=${!b}
    frames[$b]=$(frames_for "$bin")
    rates[$b]=""
done
echo "preset $preset, ${viewer_args[*]}, $(date -u +%F), frames: before ${frames[before]}, after ${frames[after]}"
for r in $(seq "$rounds"); do
    order="before after"
    if (( r % 2 == 0 )); then order="after before"; fi
    for b in $order; do
        bin=${!b}
        line=$(quality "$bin" "${frames[$b]}")
        read -r s rate <<<"$(field "$line")"
        echo "round $r $b: $s s, $rate spp/s"
        rates[$b]="${rates[$b]} $rate"
    done
done
python3 - "${rates[before]}" "${rates[after]}" <<'EOF'
import sys
before = [float(x) for x in sys.argv[1].split()]
after = [float(x) for x in sys.argv[2].split()]
mb, ma = sum(before) / len(before), sum(after) / len(after)
print(f"mean before {mb:.2f} spp/s, after {ma:.2f} spp/s: after / before = {ma / mb:.2f}")
EOF
