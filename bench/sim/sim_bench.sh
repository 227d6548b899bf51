#!/usr/bin/env bash
# ./edm bench sim — the simulator's speed (simulated seconds per wall second, drill preset with
# the 1 kHz servo program on the virtual clock) and the drilling calibration plot of
# docs/simulator.md (gnuplot): depth vs time, drilling speed and debris vs depth/diameter.
#   bench/sim/sim_bench.sh EDMPLC ROOT [SIM_SECONDS]
set -euo pipefail
edmplc=$1
root=$2
calib_s=${3:-300}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

echo "== speed: drill-sim, 30 s of virtual time, 3 runs"
ratios=()
for i in 1 2 3; do
  t0=$(date +%s.%N)
  "$edmplc" --config "$root/config/machines/drill-sim.yaml" --clock virtual --run-for 30s \
    --log-level warn
  t1=$(date +%s.%N)
  r=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", 30 / (b - a) }')
  echo "  run $i: $(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f", b - a }') s wall -> ${r}x real time"
  ratios+=("$r")
done
median=$(printf '%s\n' "${ratios[@]}" | sort -g | sed -n 2p)
echo "  median: ${median}x real time (target >= 100x)"

echo "== calibration: drill preset, ${calib_s} s of virtual time"
"$edmplc" --config "$root/config/bench/drill-calibration.yaml" --clock virtual \
  --run-for "${calib_s}s" --trace-out "$tmp/trace.csv" --log-level warn
# Monitor rows only: t_s, depth, debris, short ratio, arc ratio.
awk -F, 'NR > 1 && $2 == "monitor" { print $1, $4, $5, $6, $7 }' "$tmp/trace.csv" > "$tmp/mon.dat"
# Drilling speed per 1 mm of depth: mm/min against depth/diameter (hole Ø1.1 mm).
awk 'BEGIN { d = 1.1; next_mm = 1 }
     { if ($2 >= next_mm) { if (t_prev != "") printf "%.3f %.3f\n", (next_mm - 0.5) / d, 60 / ($1 - t_prev);
                            t_prev = $1; next_mm += 1 } }' "$tmp/mon.dat" > "$tmp/speed.dat"
mkdir -p "$root/docs/img"
gnuplot <<GP
set terminal pngcairo size 900,900 font ",10"
set output "$root/docs/img/drill-calibration.png"
set multiplot layout 3,1 title "drill preset, default flushing (F = 1), voltage servo, seed 1"
set grid
set xlabel "time (s)"; set ylabel "depth (mm)"
plot "$tmp/mon.dat" using 1:2 with lines lw 2 title "hole depth"
set xlabel "depth / diameter"; set ylabel "drilling speed (mm/min)"
plot "$tmp/speed.dat" using 1:2 with linespoints lw 2 title "speed per mm of depth"
set ylabel "fraction"; set yrange [0:1]
plot "$tmp/mon.dat" using (\$2/1.1):3 with lines lw 2 title "debris c", \
     "$tmp/mon.dat" using (\$2/1.1):4 with lines title "short ratio (200 ms filter)", \
     "$tmp/mon.dat" using (\$2/1.1):5 with lines title "stable-arc ratio (200 ms filter)"
unset multiplot
GP
echo "  speed per mm of depth (h/d, mm/min):"
awk '{ printf "    %6.2f  %7.2f\n", $1, $2 }' "$tmp/speed.dat"
echo "  plot: docs/img/drill-calibration.png"
