#!/usr/bin/env bash
# Scaling of the splatters (docs/speed-vs-accuracy.md): time and peak memory against the
# number of visible voxels (synthetic:phantom:N, N = 64..512, 512x512 image) and against the
# image size (256^2 .. 2048^2, phantom:128), each with the fitted exponent (least-squares
# slope on log-log axes), and the speed-up from 1 thread to all.
# Usage: bash tools/bench/scaling.sh [MAX_N] [MAX_SIZE]  (after tools/build.sh; defaults
# 512 and 2048; phantom:512 needs ~3 GiB and several minutes on 2 cores)
set -euo pipefail
cd "$(dirname "$0")/../.."
S=build/bin/splat
# On a shared machine other processes distort wall times (and make the 1 -> 2 thread
# speed-up meaningless); as root, run each timing at real-time priority (SCHED_FIFO; the
# kernel still leaves 5% of every second to the rest), so the figures are this program's.
RT=()
if [ "$(id -u)" -eq 0 ] && command -v chrt > /dev/null && chrt -f 50 true 2> /dev/null; then
    RT=(chrt -f 50)
    echo "(timings at real-time priority: ${RT[*]})"
fi
MAXN=${1:-512}
MAXSIZE=${2:-2048}
ALL=$(nproc)
CH2=/usr/share/mricron/templates/ch2.nii.gz
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# bench VOLUME SIZE RENDERER THREADS -> "splats median_ms peak_MiB"
bench() {
    local tf=ct-soft
    [[ "$1" == *.nii* ]] && tf=mri-head
    "${RT[@]}" /usr/bin/time -f "%M" -o "$tmp/mem" $S bench "$1" --tf "$tf" --size "$2" --renderer "$3" \
        --azimuth 30 --elevation 15 --repeats 5 --thread-list "$4" --json "$tmp/b.json" > /dev/null
    python3 - "$tmp/b.json" "$tmp/mem" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))["runs"][0]
print(r["splats"], f"{r['median_ms']:.1f}", round(int(open(sys.argv[2]).read().split()[-1]) / 1024))
PY
}
fit() {  # file with "x y" lines -> slope of log y on log x
    python3 - "$1" <<'PY'
import math, sys
pts = [tuple(map(float, l.split())) for l in open(sys.argv[1]) if l.strip()]
xs = [math.log(p[0]) for p in pts]; ys = [math.log(p[1]) for p in pts]
n = len(xs); mx = sum(xs) / n; my = sum(ys) / n
den = sum((x - mx) ** 2 for x in xs)
print(f"{sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / den:.2f}" if den > 0 else "n/a")
PY
}
for R in axis sheet; do
    echo "## $R: against visible voxels (512x512, $ALL threads)"
    echo "| volume | visible voxels | median ms | peak MiB |"
    echo "|---|---|---|---|"
    : > "$tmp/t_$R"; : > "$tmp/m_$R"
    for N in 64 128 256 512; do
        [ "$N" -le "$MAXN" ] || continue
        read -r splats ms mib < <(bench "synthetic:phantom:$N" 512x512 $R "$ALL")
        echo "| phantom:$N | $splats | $ms | $mib |"
        echo "$splats $ms" >> "$tmp/t_$R"; echo "$splats $mib" >> "$tmp/m_$R"
    done
    echo "time exponent: $(fit "$tmp/t_$R"), memory exponent: $(fit "$tmp/m_$R")"
    echo
    echo "## $R: against image size (phantom:128, $ALL threads)"
    echo "| size | pixels | median ms | peak MiB |"
    echo "|---|---|---|---|"
    : > "$tmp/s_$R"
    for P in 256 512 1024 2048; do
        [ "$P" -le "$MAXSIZE" ] || continue
        read -r splats ms mib < <(bench synthetic:phantom:128 "${P}x${P}" $R "$ALL")
        echo "| ${P}x${P} | $((P * P)) | $ms | $mib |"
        echo "$((P * P)) $ms" >> "$tmp/s_$R"
    done
    echo "time exponent against pixels: $(fit "$tmp/s_$R")"
    echo
    for V in synthetic:phantom:128 synthetic:phantom:256 "$CH2"; do
        [ "$V" != "$CH2" ] || [ -f "$CH2" ] || continue
        read -r _ ms1 _ < <(bench "$V" 512x512 $R 1)
        read -r _ msall _ < <(bench "$V" 512x512 $R "$ALL")
        python3 -c "print(f'- $R speed-up 1 -> $ALL threads ($(basename "$V"), 512x512): {$ms1 / $msall:.2f}x ($ms1 ms -> $msall ms)')"
    done
    echo
done
