# The demo's trace (out/demo/trace.csv, written by edmplc --trace-out) against time, one panel per
# quantity. Usage: gnuplot -e "csv='out/demo/trace.csv'; png='out/demo/trace.png'" plot-trace.gp
# Columns are looked up by name, so the trace list in the machine config may change order.
set datafile separator ','
set terminal pngcairo size 1400,1500 font 'DejaVu Sans,11' noenhanced
set output png
stats csv using 1 every ::1::1 nooutput
t0 = STATS_min
set multiplot layout 5,1 title 'edmplc demo: 12 mm hole then wall finish (drill-sim machine, simulated)' font ',14'
set grid
set key outside right top
set lmargin 12
set rmargin 34
every_n = 20     # 1 kHz trace: every 20th row is enough for the eye
set xlabel ''
set format x ''
set ylabel 'position / depth [mm]'
plot csv every every_n using (column('t_s')-t0):(column('io.z_mm')) with lines lw 2 title 'Z axis (machine)', \
     '' every every_n using (column('t_s')-t0):(-column('cnc.job.drill.depth_reached_mm')) with lines lw 2 title '−depth reached (controller)', \
     '' every every_n using (column('t_s')-t0):(-column('io.depth_mm')) with lines lw 1 dt 2 title '−hole depth (simulator)'
set ylabel 'ignition delay [µs]'
set yrange [0:*]
plot csv every every_n using (column('t_s')-t0):(column('cnc.job.drill.td.td_us')) with lines lw 1 title 'Td, mean per cycle', \
     '' every every_n using (column('t_s')-t0):(column('cnc.job.drill.tdr_us')) with lines lw 2 title 'Tdr, reference'
set autoscale y
set ylabel 'Z feed [mm/s]'
plot csv every every_n using (column('t_s')-t0):(column('io.vz_cmd')) with lines lw 1 title 'Z feed command', \
     '' every every_n using (column('t_s')-t0):(column('cnc.job.drill.gap.vz_mm_s')) with lines lw 1 title 'gap controller output'
set ylabel 'electrode [mm]'
set y2label 'wall radius [mm]'
set y2tics
set ytics nomirror
plot csv every every_n using (column('t_s')-t0):(column('io.electrode_mm')) axes x1y1 with lines lw 2 title 'electrode length', \
     '' every every_n using (column('t_s')-t0):(column('io.wall_radius_mm')) axes x1y2 with lines lw 2 title 'hole wall radius'
unset y2tics
unset y2label
set ytics mirror
set xlabel 'time since edmplc start [s]'
set format x '%g'
set ylabel 'pulse ratios [%]'
set yrange [0:*]
plot csv every every_n using (column('t_s')-t0):(100*column('io.ratio_short')) with lines lw 2 title 'short circuits', \
     '' every every_n using (column('t_s')-t0):(100*(column('io.ratio_transient_arc')+column('io.ratio_stable_arc'))) with lines lw 1 title 'arcs (transient + stable)'
unset multiplot
